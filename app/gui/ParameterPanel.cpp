#include "ParameterPanel.h"

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QHBoxLayout>
#include <QProgressBar>
#include <QPushButton>
#include <QSignalBlocker>
#include <QSlider>
#include <QSpinBox>
#include <QVBoxLayout>

#include <cmath>

namespace tp::gui {

namespace {

constexpr double kSliderDepth = 3.0;  // µm at the slider's end (the spin box goes further)
constexpr int kSliderSteps = 300;     // 0.01 µm per step

QDoubleSpinBox* spin(double lo, double hi, int decimals, double step, const QString& suffix,
                     const QString& tip) {
  auto* s = new QDoubleSpinBox;
  s->setRange(lo, hi);
  s->setDecimals(decimals);
  s->setSingleStep(step);
  s->setSuffix(suffix);
  s->setToolTip(tip);
  s->setKeyboardTracking(false);  // one change per edit, not per keystroke
  s->setAccelerated(true);
  return s;
}

}  // namespace

ParameterPanel::ParameterPanel(QWidget* parent) : QWidget(parent) {
  setObjectName("parameterPanel");
  auto* layout = new QVBoxLayout(this);
  layout->addWidget(buildMaterialGroup());
  layout->addWidget(buildDepthGroup());
  layout->addWidget(buildScheduleGroup());
  layout->addStretch(1);
  setParams(SimulationParams{});
  setSchedule(Schedule{});
  setRunning(false);
}

QWidget* ParameterPanel::buildMaterialGroup() {
  auto* box = new QGroupBox(tr("Tissue and probe"));
  auto* form = new QFormLayout(box);
  E_ = spin(0.1, 10000, 1, 10, tr(" MPa"),
            tr("Young's modulus E of the cell walls (MPa). AFM on the meristem's outer wall reads "
               "1.5–5 MPa apparent; measured wall moduli span 1–1000 MPa."));
  nu_ = spin(0.0, 0.5, 3, 0.01, QString(),
             tr("Poisson ratio ν of the walls (the study used 0.49)."));
  h_ = spin(0.01, 5, 3, 0.05, tr(" µm"), tr("Wall thickness h (µm), typically 0.1–1 µm."));
  p_ = spin(0.0, 5, 3, 0.1, tr(" MPa"),
            tr("Turgor pressure p of every cell (MPa); about 0.8 MPa in the meristem, 0 when "
               "plasmolysed."));
  bending_ = new QComboBox;
  bending_->setObjectName("bendingCombo");
  bending_->addItem(tr("Koiter plate (with ν)"), int(BendingModel::Koiter));
  bending_->addItem(tr("hinge (no Poisson coupling)"), int(BendingModel::Hinge));
  bending_->addItem(tr("linear (published model)"), int(BendingModel::Linear));
  bending_->addItem(tr("none (membrane only)"), int(BendingModel::None));
  bending_->setToolTip(
      tr("Wall bending: the Kirchhoff–Love (Koiter) plate energy with the walls' ν, on Morley "
         "triangles (default; right at free and hinged edges and on irregular meshes); "
         "discrete-shell hinges reproducing D = E h³/(12(1−ν²)) on a cylinder but without the "
         "Poisson coupling; the linear bending vector of Volino & Magnenat-Thalmann (the "
         "published model, about 3× too soft); or no bending."));
  junctions_ = new QComboBox;
  junctions_->setObjectName("junctionsCombo");
  junctions_->addItem(tr("hinged (walls pivot)"), int(JunctionRule::Hinged));
  junctions_->addItem(tr("rigid (angles kept)"), int(JunctionRule::Rigid));
  junctions_->setToolTip(
      tr("How walls meeting at a junction share rotation under Koiter bending: hinged — each "
         "wall pivots freely about the junction (the outer surface still bends as one sheet); "
         "rigid — the angles between the walls are kept, as in a welded frame."));
  radius_ = spin(0.05, 20, 2, 0.1, tr(" µm"),
                 tr("Radius of the spherical probe (µm): from 1/15 of a cell to half a cell."));
  mesh_ = new QComboBox;
  mesh_->setObjectName("meshCombo");
  mesh_->addItem(tr("automatic"), -1);
  mesh_->addItem(tr("level 0 (as loaded)"), 0);
  for (int level = 1; level <= MeshSettings{}.maxLevel; ++level)
    mesh_->addItem(tr("level %1 (triangles of r/%2)").arg(level).arg(1 << (level - 1)), level);
  mesh_->setToolTip(
      tr("The mesh around the site. Automatic: refined level by level until the estimated "
         "discretisation error of the force is within the tolerance (each curve shows its "
         "error). A fixed level L has triangles of probe radius / 2^(L−1) under the probe, "
         "graded out to the tissue's own; level 0 is the tissue as loaded."));
  tolerance_ = spin(0.5, 50, 1, 0.5, tr(" %"),
                    tr("Relative discretisation error asked of the automatic mesh (of the force "
                       "at the deepest point of a curve)."));
  form->addRow(tr("E"), E_);
  form->addRow(tr("ν"), nu_);
  form->addRow(tr("Wall thickness h"), h_);
  form->addRow(tr("Turgor p"), p_);
  form->addRow(tr("Bending"), bending_);
  form->addRow(tr("Junctions"), junctions_);
  form->addRow(tr("Probe radius"), radius_);
  junctionBand_ = new QCheckBox(tr("Band along the junctions"));
  junctionBand_->setObjectName("junctionBandCheck");
  junctionBand_->setToolTip(
      tr("Also refine a band along the junctions of the probed cell to the width of the walls' "
         "bending layer under turgor, √(D/N) (about 0.3 µm on the default walls). Slower (about "
         "twice the time per level); shows how much a result depends on those layers, which "
         "the default mesh resolves only at finer levels."));
  form->addRow(tr("Mesh"), mesh_);
  form->addRow(tr("Mesh tolerance"), tolerance_);
  form->addRow(QString(), junctionBand_);

  auto* presets = new QHBoxLayout;
  auto* turgid = new QPushButton(tr("Turgid"));
  turgid->setToolTip(tr("Preset: turgor p = 0.8 MPa"));
  auto* plasmolysed = new QPushButton(tr("Plasmolysed"));
  plasmolysed->setToolTip(tr("Preset: turgor p = 0 (cells emptied of pressure)"));
  presets->addWidget(turgid);
  presets->addWidget(plasmolysed);
  form->addRow(tr("Presets"), presets);
  connect(turgid, &QPushButton::clicked, this, &ParameterPanel::applyTurgidPreset);
  connect(plasmolysed, &QPushButton::clicked, this, &ParameterPanel::applyPlasmolysedPreset);

  for (auto* s : {E_, nu_, h_, p_, radius_, tolerance_})
    connect(s, &QDoubleSpinBox::valueChanged, this, &ParameterPanel::emitParams);
  connect(mesh_, &QComboBox::currentIndexChanged, this, &ParameterPanel::emitParams);
  connect(junctionBand_, &QCheckBox::toggled, this, &ParameterPanel::emitParams);
  connect(bending_, &QComboBox::currentIndexChanged, this, [this] {
    junctions_->setEnabled(bending_->currentData().toInt() == int(BendingModel::Koiter));
    emitParams();
  });
  connect(junctions_, &QComboBox::currentIndexChanged, this, &ParameterPanel::emitParams);
  return box;
}

QWidget* ParameterPanel::buildDepthGroup() {
  auto* box = new QGroupBox(tr("Probe depth"));
  auto* row = new QHBoxLayout(box);
  depth_ = spin(0, 10, 3, 0.05, tr(" µm"),
                tr("Probe travel from first contact (µm). Also: right-drag or Ctrl+left-drag "
                   "vertically in the 3D view."));
  depth_->setObjectName("depthSpinBox");
  depthSlider_ = new QSlider(Qt::Horizontal);
  depthSlider_->setRange(0, kSliderSteps);
  depthSlider_->setToolTip(tr("Probe depth, 0–%1 µm").arg(kSliderDepth));
  row->addWidget(depthSlider_, 1);
  row->addWidget(depth_);
  connect(depthSlider_, &QSlider::valueChanged, this,
          [this](int v) { depth_->setValue(v * kSliderDepth / kSliderSteps); });
  connect(depth_, &QDoubleSpinBox::valueChanged, this, [this](double d) {
    const QSignalBlocker block(depthSlider_);
    depthSlider_->setValue(int(std::lround(d / kSliderDepth * kSliderSteps)));
    if (!silent_) emit depthChanged(d);
  });
  return box;
}

QWidget* ParameterPanel::buildScheduleGroup() {
  auto* box = new QGroupBox(tr("Curve"));
  auto* form = new QFormLayout(box);
  control_ = new QComboBox;
  control_->addItem(tr("depth (displacement)"), int(Control::Depth));
  control_->addItem(tr("force"), int(Control::Force));
  control_->setToolTip(
      tr("Load by prescribing the probe's depth, or its force (the depth is "
         "then solved for)."));
  maxDepth_ = spin(0.001, 10, 3, 0.1, tr(" µm"), tr("Deepest point of the loading (µm)."));
  maxForce_ = spin(0.001, 1e4, 3, 1, tr(" µN"), tr("Largest force of the loading (µN)."));
  steps_ = new QSpinBox;
  steps_->setRange(1, 200);
  steps_->setKeyboardTracking(false);
  steps_->setToolTip(tr("Number of loading steps (each one equilibrium)."));
  unload_ = new QCheckBox(tr("Unload back to zero"));
  unload_->setToolTip(
      tr("After loading, go back in the same steps (for an elastic tissue the "
         "curves coincide)."));
  form->addRow(tr("Control"), control_);
  form->addRow(tr("Max depth"), maxDepth_);
  form->addRow(tr("Max force"), maxForce_);
  form->addRow(tr("Steps"), steps_);
  form->addRow(QString(), unload_);
  auto* buttons = new QHBoxLayout;
  run_ = new QPushButton(QIcon(":/icons/run.svg"), tr("Run curve"));
  run_->setObjectName("runButton");
  run_->setToolTip(tr("Run the whole schedule from depth 0 (Space)"));
  cancel_ = new QPushButton(QIcon(":/icons/cancel.svg"), tr("Cancel"));
  cancel_->setObjectName("cancelButton");
  cancel_->setToolTip(tr("Stop after the current point (Esc)"));
  buttons->addWidget(run_);
  buttons->addWidget(cancel_);
  form->addRow(buttons);
  progress_ = new QProgressBar;
  progress_->setObjectName("runProgressBar");
  progress_->setTextVisible(true);
  form->addRow(progress_);
  connect(run_, &QPushButton::clicked, this, &ParameterPanel::runRequested);
  connect(cancel_, &QPushButton::clicked, this, &ParameterPanel::cancelRequested);
  for (auto* s : {maxDepth_, maxForce_})
    connect(s, &QDoubleSpinBox::valueChanged, this, &ParameterPanel::emitSchedule);
  connect(steps_, &QSpinBox::valueChanged, this, &ParameterPanel::emitSchedule);
  connect(unload_, &QCheckBox::toggled, this, &ParameterPanel::emitSchedule);
  connect(control_, &QComboBox::currentIndexChanged, this, &ParameterPanel::emitSchedule);
  return box;
}

SimulationParams ParameterPanel::params() const {
  SimulationParams p;
  p.youngModulus = E_->value();
  p.poissonRatio = nu_->value();
  p.thickness = h_->value();
  p.pressure = p_->value();
  p.bending = static_cast<BendingModel>(bending_->currentData().toInt());
  p.junctions = static_cast<JunctionRule>(junctions_->currentData().toInt());
  p.probeRadius = radius_->value();
  const int level = mesh_->currentData().toInt();
  p.autoMesh = level < 0;
  p.meshLevel = level < 0 ? lastParams_.meshLevel : level;
  p.meshTolerance = tolerance_->value() / 100.0;
  p.junctionBand = junctionBand_->isChecked();
  return p;
}

Schedule ParameterPanel::schedule() const {
  Schedule s;
  s.control = static_cast<Control>(control_->currentData().toInt());
  s.maxDepth = maxDepth_->value();
  s.maxForce = maxForce_->value();
  s.steps = steps_->value();
  s.unload = unload_->isChecked();
  return s;
}

double ParameterPanel::depth() const {
  return depth_->value();
}

void ParameterPanel::setParams(const SimulationParams& p) {
  silent_ = true;
  E_->setValue(p.youngModulus);
  nu_->setValue(p.poissonRatio);
  h_->setValue(p.thickness);
  p_->setValue(p.pressure);
  bending_->setCurrentIndex(bending_->findData(int(p.bending)));
  junctions_->setCurrentIndex(junctions_->findData(int(p.junctions)));
  junctions_->setEnabled(p.bending == BendingModel::Koiter);
  radius_->setValue(p.probeRadius);
  mesh_->setCurrentIndex(std::max(0, mesh_->findData(p.autoMesh ? -1 : p.meshLevel)));
  tolerance_->setValue(100.0 * p.meshTolerance);
  tolerance_->setEnabled(p.autoMesh);
  junctionBand_->setChecked(p.junctionBand);
  updateBandControl(p);
  silent_ = false;
  lastParams_ = params();
}

void ParameterPanel::setSchedule(const Schedule& s) {
  silent_ = true;
  control_->setCurrentIndex(control_->findData(int(s.control)));
  maxDepth_->setValue(s.maxDepth);
  maxForce_->setValue(s.maxForce);
  steps_->setValue(s.steps);
  unload_->setChecked(s.unload);
  silent_ = false;
  lastSchedule_ = schedule();
  updateScheduleControls();
}

void ParameterPanel::updateBandControl(const SimulationParams& p) {
  // Without turgor or bending the walls have no bending layer at their junctions: no band.
  SimulationParams banded = p;
  banded.junctionBand = true;
  junctionBand_->setEnabled(junctionBandApplies(banded.experimentSettings()));
}

void ParameterPanel::emitParams() {
  if (silent_) return;
  const SimulationParams p = params();
  tolerance_->setEnabled(p.autoMesh);
  updateBandControl(p);
  if (p == lastParams_) return;
  lastParams_ = p;
  emit paramsChanged(p);
}

void ParameterPanel::emitSchedule() {
  updateScheduleControls();
  if (silent_) return;
  const Schedule s = schedule();
  if (s == lastSchedule_) return;
  lastSchedule_ = s;
  emit scheduleChanged(s);
}

void ParameterPanel::updateScheduleControls() {
  const bool force = control_->currentData().toInt() == int(Control::Force);
  maxDepth_->setEnabled(!force);
  maxForce_->setEnabled(force);
}

void ParameterPanel::setDepth(double depth) {
  depth_->setValue(depth);
}

void ParameterPanel::showDepth(double depth) {
  silent_ = true;
  depth_->setValue(depth);
  silent_ = false;
}

void ParameterPanel::setRunning(bool running) {
  run_->setEnabled(!running);
  cancel_->setEnabled(running);
  depth_->setEnabled(!running);
  depthSlider_->setEnabled(!running);
  if (running) progress_->setValue(0);
}

void ParameterPanel::setProgress(int done, int total) {
  progress_->setRange(0, total);
  progress_->setValue(done);
}

// Presets go through the widgets, so a change is reported like an edit (and no change is not).
void ParameterPanel::applyTurgidPreset() {
  p_->setValue(turgidPreset(params()).pressure);
}

void ParameterPanel::applyPlasmolysedPreset() {
  p_->setValue(plasmolysedPreset(params()).pressure);
}

}  // namespace tp::gui
