#pragma once
// The parameter dock: material, turgor, probe and mesh (with units and tooltips), the
// Turgid/Plasmolysed presets, the probe depth (spin box + slider) and the loading schedule with
// Run/Cancel and a progress bar. Setters are silent; user edits emit signals.

#include <QWidget>

#include "Parameters.h"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QProgressBar;
class QPushButton;
class QSlider;
class QSpinBox;

namespace tp::gui {

class ParameterPanel : public QWidget {
  Q_OBJECT

 public:
  explicit ParameterPanel(QWidget* parent = nullptr);

  SimulationParams params() const;
  Schedule schedule() const;
  double depth() const;
  QDoubleSpinBox* depthSpinBox() const { return depth_; }

 public slots:
  void setParams(const tp::gui::SimulationParams& p);
  void setSchedule(const tp::gui::Schedule& s);
  /// As if the user set the depth (µm): emits depthChanged when it changes.
  void setDepth(double depth);
  /// Shows a depth without emitting (the worker moved the probe, e.g. during a run).
  void showDepth(double depth);
  void setRunning(bool running);
  void setProgress(int done, int total);
  void applyTurgidPreset();
  void applyPlasmolysedPreset();

 signals:
  void paramsChanged(const tp::gui::SimulationParams& p);
  void scheduleChanged(const tp::gui::Schedule& s);
  void depthChanged(double depth);
  void runRequested();
  void cancelRequested();

 private:
  QWidget* buildMaterialGroup();
  QWidget* buildDepthGroup();
  QWidget* buildScheduleGroup();
  void emitParams();
  void emitSchedule();
  void updateScheduleControls();
  void updateBandControl(const SimulationParams& p);

  QDoubleSpinBox *E_, *nu_, *h_, *p_, *radius_, *tolerance_;
  QComboBox* bending_;
  QComboBox* junctions_;
  QComboBox* mesh_;
  QDoubleSpinBox* depth_;
  QSlider* depthSlider_;
  QComboBox* control_;
  QDoubleSpinBox *maxDepth_, *maxForce_;
  QSpinBox* steps_;
  QCheckBox* unload_;
  QCheckBox* junctionBand_;
  QPushButton *run_, *cancel_;
  QProgressBar* progress_;
  bool silent_ = false;
  SimulationParams lastParams_;
  Schedule lastSchedule_;
};

}  // namespace tp::gui
