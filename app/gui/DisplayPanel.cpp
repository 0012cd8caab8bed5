#include "DisplayPanel.h"

#include <algorithm>
#include <cmath>

#include <QCheckBox>
#include <QComboBox>
#include <QDoubleSpinBox>
#include <QFormLayout>
#include <QGroupBox>
#include <QSignalBlocker>
#include <QSlider>
#include <QVBoxLayout>

#include "MapValues.h"

namespace tp::gui {

namespace {

QDoubleSpinBox* rangeBox(const QString& tip) {
  auto* s = new QDoubleSpinBox;
  s->setRange(-1e6, 1e6);
  s->setDecimals(4);
  s->setKeyboardTracking(false);
  s->setToolTip(tip);
  return s;
}

}  // namespace

DisplayPanel::DisplayPanel(QWidget* parent) : QWidget(parent) {
  setObjectName("displayPanel");
  auto* layout = new QVBoxLayout(this);

  auto* colour = new QGroupBox(tr("Colour"));
  auto* form = new QFormLayout(colour);
  field_ = new QComboBox;
  field_->setObjectName("quantity");
  for (int f = 0; f < kFieldCount; ++f)
    field_->addItem(QString::fromUtf8(fieldName(Field(f))) + " (" +
                        QString::fromUtf8(fieldUnit(Field(f))) + ")",
                    f);
  field_->insertSeparator(kFieldCount);
  for (int v = 0; v < MapField::kValueCount; ++v)
    field_->addItem(QString::fromUtf8(mapValueInfo(v).name) + " (" +
                        QString::fromUtf8(mapValueInfo(v).unit) + ")",
                    kMapItem + v);
  field_->setToolTip(
      tr("Quantity that colours each wall triangle: in-plane stresses and "
         "energy densities from the stress read-out (MPa), the displacement "
         "from the turgid state (µm), or the stress the probe adds: the change "
         "from the turgid state (MPa, on the diverging map). The stiffness map's values "
         "(Simulation ▸ Stiffness map) colour the outer surface, interpolated between the "
         "map's sites; then a click on a site shows its curve."));
  map_ = new QComboBox;
  for (int k = 0; k < ColorMap::kKindCount; ++k)
    map_->addItem(QString::fromUtf8(ColorMap::name(ColorMap::Kind(k))), k);
  map_->setToolTip(
      tr("Viridis for magnitudes; cool–warm for signed values (zero in the middle "
         "when the automatic range spans both signs)."));
  auto_ = new QCheckBox(tr("Automatic range"));
  auto_->setChecked(true);
  auto_->setToolTip(tr("Follow the smallest and largest value of the current state."));
  lo_ = rangeBox(tr("Value at the low end of the colour bar"));
  hi_ = rangeBox(tr("Value at the high end of the colour bar"));
  lo_->setEnabled(false);
  hi_->setEnabled(false);
  outlines_ = new QCheckBox(tr("Cell outlines"));
  outlines_->setChecked(true);
  outlines_->setToolTip(tr("Draw the boundaries of the walls (where cells meet) as lines."));
  form->addRow(tr("Quantity"), field_);
  form->addRow(tr("Colour map"), map_);
  form->addRow(auto_);
  form->addRow(tr("Min"), lo_);
  form->addRow(tr("Max"), hi_);
  form->addRow(outlines_);
  mesh_ = new QCheckBox(tr("Mesh (triangles)"));
  mesh_->setObjectName("meshCheckBox");
  mesh_->setToolTip(tr("Draw every triangle's edges: the mesh is refined around the site so "
                       "that the force does not depend on it (see the mesh level and its "
                       "estimated error in the status bar)."));
  form->addRow(mesh_);
  glyphs_ = new QCheckBox(tr("Principal directions"));
  glyphs_->setObjectName("glyphsCheckBox");
  glyphs_->setToolTip(tr("A short line on every triangle along its largest principal stress, "
                         "longer where that stress is larger: how the walls are pulled"));
  form->addRow(glyphs_);
  deformation_ = new QDoubleSpinBox;
  deformation_->setObjectName("deformationScale");
  deformation_->setRange(1.0, 50.0);
  deformation_->setDecimals(0);
  deformation_->setSingleStep(5.0);
  deformation_->setPrefix(tr("×"));
  deformation_->setValue(1.0);
  deformation_->setToolTip(
      tr("Draw the displacement from the turgid state magnified: a 1 µm dimple under a 1 µm "
         "probe on a 40 µm dome is hard to see at ×1. The numbers (depth, force, fields) stay "
         "true; the view says \"displacement ×N\" while N > 1."));
  form->addRow(tr("Displacement"), deformation_);
  connect(deformation_, &QDoubleSpinBox::valueChanged, this,
          &DisplayPanel::deformationScaleChanged);
  layout->addWidget(colour);

  auto* sectionBox = new QGroupBox(tr("Section"));
  auto* sform = new QFormLayout(sectionBox);
  section_ = new QCheckBox(tr("Cut the tissue"));
  section_->setObjectName("sectionCheckBox");
  section_->setToolTip(tr("Clip the tissue with a plane to see the inner walls."));
  axis_ = new QComboBox;
  axis_->addItems({tr("x (normal to x)"), tr("y (normal to y)"), tr("z (normal to z)")});
  axis_->setCurrentIndex(1);
  position_ = new QSlider(Qt::Horizontal);
  position_->setRange(0, 1000);
  position_->setValue(500);
  position_->setToolTip(tr("Position of the plane across the tissue's extent along the axis"));
  flip_ = new QCheckBox(tr("Keep the other side"));
  sform->addRow(section_);
  sform->addRow(tr("Axis"), axis_);
  sform->addRow(tr("Position"), position_);
  sform->addRow(flip_);
  layout->addWidget(sectionBox);
  layout->addStretch(1);

  connect(field_, &QComboBox::currentIndexChanged, this, [this] {
    // A change from the turgid state is signed: shown on the diverging map (zero in the
    // middle); back on a magnitude, the map it had before.
    const bool change = mapValue() < 0 && quantityInfo(field()).change;
    if (change != lastFieldWasChange_) {
      const int wanted = change ? int(ColorMap::Kind::CoolWarm) : int(ColorMap::Kind::Viridis);
      map_->setCurrentIndex(map_->findData(wanted));
      lastFieldWasChange_ = change;
    }
    updateUnits();
    if (mapValue() < 0) {
      lastField_ = field();
      emit fieldChanged(field());
    }
    emit mapValueChanged(mapValue());
  });
  connect(map_, &QComboBox::currentIndexChanged, this,
          [this] { emit colorMapChanged(colorMapKind()); });
  connect(auto_, &QCheckBox::toggled, this, [this](bool on) {
    lo_->setEnabled(!on);
    hi_->setEnabled(!on);
    emit autoRangeChanged(on);
    if (!on) emit rangeChanged(lo_->value(), hi_->value());
  });
  for (auto* s : {lo_, hi_})
    connect(s, &QDoubleSpinBox::valueChanged, this, [this] {
      if (!auto_->isChecked()) emit rangeChanged(lo_->value(), hi_->value());
    });
  connect(outlines_, &QCheckBox::toggled, this, &DisplayPanel::outlinesChanged);
  connect(mesh_, &QCheckBox::toggled, this, &DisplayPanel::meshChanged);
  connect(glyphs_, &QCheckBox::toggled, this, &DisplayPanel::glyphsChanged);
  connect(section_, &QCheckBox::toggled, this, &DisplayPanel::emitSection);
  connect(axis_, &QComboBox::currentIndexChanged, this, &DisplayPanel::emitSection);
  connect(position_, &QSlider::valueChanged, this, &DisplayPanel::emitSection);
  connect(flip_, &QCheckBox::toggled, this, &DisplayPanel::emitSection);
  updateUnits();
}

Field DisplayPanel::field() const {
  const int d = field_->currentData().toInt();
  return d >= kMapItem ? lastField_ : Field(d);
}

int DisplayPanel::mapValue() const {
  const int d = field_->currentData().toInt();
  return d >= kMapItem ? d - kMapItem : -1;
}

void DisplayPanel::showMapValue(int v) {
  if (v >= 0 && v < MapField::kValueCount) field_->setCurrentIndex(field_->findData(kMapItem + v));
}

ColorMap::Kind DisplayPanel::colorMapKind() const {
  return ColorMap::Kind(map_->currentData().toInt());
}

bool DisplayPanel::sectionEnabled() const {
  return section_->isChecked();
}

void DisplayPanel::setSectionEnabled(bool on) {
  section_->setChecked(on);
}

DisplaySettings DisplayPanel::settings() const {
  DisplaySettings d;
  d.quantity = mapValue() >= 0 ? mapValueInfo(mapValue()).key : fieldKey(field());
  d.colourMap = ColorMap::key(colorMapKind());
  d.autoRange = auto_->isChecked();
  d.lo = lo_->value();
  d.hi = hi_->value();
  d.outlines = outlines_->isChecked();
  d.mesh = mesh_->isChecked();
  d.glyphs = glyphs_->isChecked();
  d.deformationScale = deformation_->value();
  d.section = section_->isChecked();
  d.sectionAxis = axis_->currentIndex();
  d.sectionPosition = position_->value() / 1000.0;
  d.keepOtherSide = flip_->isChecked();
  return d;
}

void DisplayPanel::applySettings(const DisplaySettings& d) {
  const int q = quantityIndex(d.quantity);
  if (q >= 0) field_->setCurrentIndex(field_->findData(q));
  if (const int v = mapValueIndex(d.quantity); v >= 0) showMapValue(v);
  // After the quantity, whose change may switch the map.
  for (int k = 0; k < ColorMap::kKindCount; ++k)
    if (d.colourMap == ColorMap::key(ColorMap::Kind(k))) map_->setCurrentIndex(map_->findData(k));
  auto_->setChecked(true);  // the manual numbers go in while the boxes are the view's
  lo_->setValue(d.lo);
  hi_->setValue(d.hi);
  auto_->setChecked(d.autoRange);
  outlines_->setChecked(d.outlines);
  mesh_->setChecked(d.mesh);
  glyphs_->setChecked(d.glyphs);
  deformation_->setValue(d.deformationScale);
  axis_->setCurrentIndex(std::clamp(d.sectionAxis, 0, 2));
  position_->setValue(int(std::lround(1000 * std::clamp(d.sectionPosition, 0.0, 1.0))));
  flip_->setChecked(d.keepOtherSide);
  section_->setChecked(d.section);
}

void DisplayPanel::updateUnits() {
  const QString unit =
      QStringLiteral(" ") + QString::fromUtf8(mapValue() >= 0 ? mapValueInfo(mapValue()).unit
                                                              : fieldUnit(field()));
  lo_->setSuffix(unit);
  hi_->setSuffix(unit);
}

void DisplayPanel::showRange(double lo, double hi) {
  if (!auto_->isChecked()) return;  // the user's numbers stay
  const QSignalBlocker a(lo_), b(hi_);
  lo_->setValue(lo);
  hi_->setValue(hi);
}

void DisplayPanel::emitSection() {
  emit sectionChanged(section_->isChecked(), axis_->currentIndex(), position_->value() / 1000.0,
                      flip_->isChecked());
}

}  // namespace tp::gui
