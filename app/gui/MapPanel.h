#pragma once
// The Stiffness map dock: which sites (cell middles, junctions, a grid), how deep, how many
// workers; Start and Cancel; the progress (sites done, rate, time left) and, once sites are
// done, the spread of their stiffness. It starts maps on the MapRunner with the window's
// current tissue and parameters; the colours and the clicks are the view's.

#include <QString>
#include <QWidget>

class QComboBox;
class QDoubleSpinBox;
class QLabel;
class QProgressBar;
class QPushButton;
class QSpinBox;

namespace tp::gui {

class MapRunner;
class SimulationController;

class MapPanel : public QWidget {
  Q_OBJECT

 public:
  MapPanel(MapRunner* runner, SimulationController* controller, QWidget* parent = nullptr);

  /// Where maps' results folders go (default: the user's cache folder, "maps").
  void setCacheRoot(const QString& dir) { cacheRoot_ = dir; }
  const QString& cacheRoot() const { return cacheRoot_; }

 public slots:
  /// Starts the map the controls describe (the Start button); errors in a message box.
  bool startMap();

 signals:
  /// The map has sites done and the user asked to see it (Show on the tissue).
  void showRequested();
  void statusMessage(const QString& text);

 private:
  void updateState();
  void updateSummary();

  MapRunner* runner_;
  SimulationController* controller_;
  QComboBox* sites_;
  QDoubleSpinBox *spacing_, *depth_;
  QSpinBox *steps_, *jobs_;
  QPushButton *start_, *cancel_, *show_;
  QProgressBar* progress_;
  QLabel *status_, *summary_, *note_;
  QString cacheRoot_;
};

}  // namespace tp::gui
