#pragma once
// The colour and section dock: which quantity colours the walls, the colour map, the range
// (automatic or min/max in the quantity's unit), cell outlines, and the section plane (on/off,
// axis, position along the tissue, side kept).

#include <QWidget>

#include "ColorMap.h"
#include "SessionFile.h"
#include "Snapshot.h"

class QCheckBox;
class QComboBox;
class QDoubleSpinBox;
class QSlider;

namespace tp::gui {

class DisplayPanel : public QWidget {
  Q_OBJECT

 public:
  explicit DisplayPanel(QWidget* parent = nullptr);

  /// The quantity chosen (while a map value is, the quantity chosen before it).
  Field field() const;
  /// The stiffness map's value chosen (MapValues.h), or −1.
  int mapValue() const;
  ColorMap::Kind colorMapKind() const;
  bool sectionEnabled() const;
  /// Everything this dock sets, for a session (the camera is left empty: it is the view's).
  DisplaySettings settings() const;
  /// Sets every control (each emits its signal, so the view follows).
  void applySettings(const DisplaySettings& d);

 public slots:
  /// The range the view uses (shown in the min/max boxes while the range is automatic).
  void showRange(double lo, double hi);
  void setSectionEnabled(bool on);
  /// Chooses map value `v` in the quantity menu.
  void showMapValue(int v);

 signals:
  void fieldChanged(tp::gui::Field field);
  void mapValueChanged(int value);
  void colorMapChanged(tp::gui::ColorMap::Kind kind);
  void autoRangeChanged(bool on);
  void rangeChanged(double lo, double hi);
  void outlinesChanged(bool on);
  void meshChanged(bool on);
  void glyphsChanged(bool on);
  void sectionChanged(bool enabled, int axis, double fraction, bool flip);
  void deformationScaleChanged(double scale);

 private:
  void emitSection();
  void updateUnits();

  QComboBox *field_, *map_, *axis_;
  QCheckBox *auto_, *outlines_, *mesh_, *glyphs_, *section_, *flip_;
  QDoubleSpinBox *lo_, *hi_, *deformation_;
  QSlider* position_;
  bool lastFieldWasChange_ = false;
  Field lastField_ = Field::VonMises;
  static constexpr int kMapItem = 1000;  // item data of the map values: kMapItem + value
};

}  // namespace tp::gui
