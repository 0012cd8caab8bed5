#pragma once
// Opening, saving and exporting, with and without dialogs: tissues (PLY) and sessions (JSON),
// the plot (PNG/SVG/PDF), the curves (CSV), a screenshot of the 3D view (PNG at a chosen size),
// the deformed state (VTU, written by the worker) and the stiffness map (CSV, VTU); a session
// holds the map too. Every write is atomic. Errors appear in
// a message box that does not block (tests keep running); the dialog-free functions return them.

#include <QObject>
#include <QSize>
#include <QString>

#include <memory>
#include <optional>

class QWidget;

namespace tp::gui {

class Autosave;
class DisplayPanel;
class MapRunner;
class PlotPanel;
class SimulationController;
class TissueView;

/// A warning box that names the problem, shown without blocking the event loop.
void showError(QWidget* parent, const QString& title, const QString& text);

class FileActions : public QObject {
  Q_OBJECT

 public:
  FileActions(QWidget* window, SimulationController* controller, TissueView* view, PlotPanel* plot,
              DisplayPanel* display, MapRunner* map);
  ~FileActions() override;

  /// A session (*.json) or a tissue (anything else).
  void open(const QString& path);
  void openTissue(const QString& path);
  bool openSession(const QString& path, QString* error);
  bool saveSession(const QString& path, QString* error);
  /// Writes the session as saveSession does, but as a copy: the curves stay unsaved and the
  /// file is not a recent one (the autosave).
  bool writeSessionCopy(const QString& path, QString* error);
  /// Every curve in one long-format CSV (a `curve` column).
  bool exportCurves(const QString& path, QString* error);
  /// The selected curve (else the newest) as tp::writeCurveCsv writes it.
  bool exportCurrentCurve(const QString& path, QString* error);
  bool exportScreenshot(const QString& path, const QSize& size, QString* error);
  /// A figure for slides and papers: the 3D view (with its colour bar and overlay) on the left
  /// and the curves on the right (legend as `legend` says, an index of
  /// PlotPanel::ExportOptions::Legend), side by side in one PNG (`size` in pixels, drawn for
  /// `dpi`) or PDF (`size` in points; the curves as vectors).
  bool exportFigure(const QString& path, const QSize& size, double dpi, int legend,
                    QString* error);
  /// A measured force–indentation curve (a table with units in its header, or a JPK text
  /// export converted at `contactHeight`, µm, else at its estimated contact point) added to the
  /// plot. False with a message naming the file, line and value.
  bool importMeasuredCurve(const QString& path, QString* error,
                           std::optional<double> contactHeight = std::nullopt);
  /// The stiffness map's table (CSV) and its surface (VTU), as `tissueprobe-cli map` writes them.
  bool exportMapTable(const QString& path, QString* error);
  bool exportMapSurface(const QString& path, QString* error);

  /// Autosave: from now on the session is written aside every minute while curves are unsaved.
  void startAutosave();
  Autosave* autosave() const { return autosave_.get(); }
  /// Writes the autosave now if there are unsaved curves (else removes it: nothing to lose).
  void autosaveNow();
  /// Offers to recover the newest session a crashed window left (asked once at start).
  void offerRecovery();

 public slots:
  void openTissueDialog();
  void openSessionDialog();
  bool saveSessionDialog();  // false when cancelled or not written
  void exportPlotDialog();
  void exportCurvesDialog();
  void exportCurrentCurveDialog();
  void exportScreenshotDialog();
  void exportFigureDialog();
  void exportVtuDialog();
  void importMeasuredCurveDialog();
  void exportMapTableDialog();
  void exportMapSurfaceDialog();

 signals:
  void recentFilesChanged();
  void statusMessage(const QString& text);

 private:
  QString askSave(const QString& title, const QString& name, const QString& filter);
  void report(bool ok, const QString& what, const QString& path, const QString& error);

  QWidget* window_;
  SimulationController* controller_;
  TissueView* view_;
  PlotPanel* plot_;
  DisplayPanel* display_;
  MapRunner* map_;
  std::unique_ptr<Autosave> autosave_;
};

}  // namespace tp::gui
