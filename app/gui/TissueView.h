#pragma once
// The 3D view: draws the newest Snapshot (walls coloured by a field, outlines, clamped base,
// probe, colour bar) and turns mouse and keys into camera moves, hover, site picks and probe
// drags. It never computes mechanics: picks and drags leave as signals.
//   left drag: orbit · shift+left or middle drag: pan · wheel: zoom · left click: indentation
//   site · right drag or ctrl+left drag (vertical): probe depth · arrows: orbit · +/-: zoom ·
//   F fit · 1/3/7 front/right/top · R reset · Z zoom to the probe.

#include <QColor>
#include <QImage>
#include <QOpenGLWidget>
#include <QPoint>
#include <QTimer>

#include <optional>
#include <tuple>

#include <memory>

#include "Camera.h"
#include "ColorMap.h"
#include "GlRenderer.h"
#include "Picking.h"
#include "SessionFile.h"
#include "Snapshot.h"
#include "SnapshotBuffers.h"
#include "experiment/Map.h"

namespace tp::gui {

class TissueView : public QOpenGLWidget {
  Q_OBJECT

 public:
  explicit TissueView(QWidget* parent = nullptr);
  ~TissueView() override;

  Camera& camera() { return camera_; }
  const Camera& camera() const { return camera_; }
  /// A site picked earlier, marked on the tissue with its number.
  struct SiteMarker {
    Eigen::Vector3d position = Eigen::Vector3d::Zero();  // µm
    int number = 0;                                      // "site N"
    QColor colour;                                       // of its curve (or grey)
    bool highlighted = false;                            // the selected curve's site
  };
  void setSiteMarkers(std::vector<SiteMarker> markers);
  const std::vector<SiteMarker>& siteMarkers() const { return markers_; }
  /// The number of the site disc drawn under a pixel (widget coordinates), or 0.
  int markerAt(const QPoint& pixel) const;
  /// Where disc `number` was last drawn on screen (widget pixels), if it was.
  std::optional<QPointF> markerCentre(int number) const;
  /// The camera's pose, for a session.
  DisplaySettings::Camera cameraPose() const;
  /// Sets the camera's pose now and again when the next tissue is shown (a session sets it
  /// before its tissue arrives, which would otherwise reset the view).
  void setCameraPose(const DisplaySettings::Camera& pose);
  const Snapshot& snapshot() const { return source_; }
  const ColorMap& colorMap() const { return map_; }
  Field field() const { return field_; }
  /// The map value the outer surface is coloured by (MapValues.h), −1 while a quantity is.
  int mapValue() const { return mapValue_; }
  /// The values drawn, one per triangle of the snapshot (a quantity's or the map's).
  const std::vector<float>& shownValues() const;
  bool autoRange() const { return autoRange_; }
  std::optional<ClipPlane> clipPlane() const;
  /// paintGL calls since creation (frames per second = difference / time).
  int frameCount() const { return frames_; }
  int highlightedCell() const { return highlight_; }

  /// The hit under a pixel (widget coordinates), honouring the section plane.
  std::optional<Hit> pickAt(const QPoint& pixel) const;
  /// Renders the view offscreen at `size` pixels (colour bar included).
  QImage renderImage(const QSize& size);

 public slots:
  void setSnapshot(const tp::gui::Snapshot& snapshot);
  /// Draws the displacement from the turgid state magnified `scale` times (1 to 50), the probe
  /// moved with it so that it stays in its dimple; numbers stay true.
  void setDeformationScale(double scale);
  double deformationScale() const { return deformationScale_; }
  /// The snapshot as drawn (positions and probe magnified by the deformation scale).
  const Snapshot& shownSnapshot() const { return snapshot_; }
  void setField(tp::gui::Field field);
  /// A stiffness map to colour the outer surface by (null: none), and where its sites are
  /// (µm, turgid surface), drawn as dots while the map is shown.
  void setMap(std::shared_ptr<const tp::MapField> map, std::vector<Eigen::Vector3d> sites);
  /// Colours the outer surface by map value `v` (0 stiffness, 1 force, 2 Hertz; −1: by the
  /// quantity again). While a map value is shown a click asks for a map site's curve.
  void setMapValue(int v);
  void setColorMapKind(tp::gui::ColorMap::Kind kind);
  void setAutoRange(bool on);
  void setRange(double lo, double hi);
  /// Section plane normal to axis 0/1/2 (x/y/z) at a fraction of the tissue's extent; `flip`
  /// keeps the other side.
  void setSection(bool enabled, int axis, double fraction, bool flip);
  void setOutlinesVisible(bool on);
  /// Draws every triangle's edges, to show where the mesh is refined around the site.
  void setMeshVisible(bool on);
  bool meshVisible() const { return mesh_; }
  /// Draws the direction of each triangle's largest principal stress as a short line.
  void setGlyphsVisible(bool on);
  bool glyphsVisible() const { return glyphs_; }
  void setRotationMode(tp::gui::Camera::RotationMode mode);
  /// Presentation (teaching) mode: the overlay text, colour bar and site labels drawn `scale`
  /// times larger (1: normal), on opaque panels.
  void setOverlayScale(double scale);
  double overlayScale() const { return overlayScale_; }
  /// What the view says while it has no tissue to draw.
  void setPlaceholder(const QString& text);
  /// The depth a probe drag starts from (µm).
  void setRequestedDepth(double depth) { requestedDepth_ = depth; }
  /// The depth a probe drag has asked for and the view shows ahead of the equilibria (µm), or
  /// −1 once an equilibrium has reached it.
  double targetDepth() const { return targetDepth_; }
  /// Forgets the target (a solve failed: the last good state is what there is).
  void clearTarget();
  void fitToView();
  void setStandardView(tp::gui::Camera::StandardView view);
  void resetView();
  /// Frames the probe's neighbourhood (a few cells around it).
  void zoomToProbe();

 signals:
  void sitePicked(int generation, int triangle, const Eigen::Vector3d& barycentric);
  /// A click while the map is shown: the material point under it (µm, rest geometry).
  void mapPointPicked(const Eigen::Vector3d& restPoint);
  void pickRejected(const QString& why);
  /// A click on a site's disc (its number): it selects that site's curve; no site is picked.
  void siteMarkerClicked(int number);
  void hoverChanged(const QString& text);
  void depthRequested(double depth);
  /// The colour range in use (auto ranges follow the data).
  void rangeChanged(double lo, double hi);
  void frameRendered();

 protected:
  void initializeGL() override;
  void resizeGL(int w, int h) override;
  void paintGL() override;
  void mousePressEvent(QMouseEvent* e) override;
  void mouseMoveEvent(QMouseEvent* e) override;
  void mouseReleaseEvent(QMouseEvent* e) override;
  void wheelEvent(QWheelEvent* e) override;
  void keyPressEvent(QKeyEvent* e) override;
  void leaveEvent(QEvent* e) override;

 private:
  enum class Drag { None, Rotate, Pan, Depth };
  void releaseGL();
  void updateRange();
  void updateHover(const QPoint& pixel);
  GlRenderer::Frame frame(const Camera& camera) const;
  void paintSiteMarkers(QPainter& p, const QSize& size, double scale) const;
  void paintOverlay(QPainter& painter, const QSize& size, double scale) const;
  void ensurePicker() const;
  void sendPendingDepth();
  double sectionPosition() const;

  Camera camera_;
  Snapshot source_;    // as the worker sent it
  Snapshot snapshot_;  // as drawn: source_ with the deformation scale applied
  double deformationScale_ = 1.0;
  double overlayScale_ = 1.0;
  void applyDeformationScale();
  ColorMap map_;
  Field field_ = Field::VonMises;
  int mapValue_ = -1;
  std::shared_ptr<const tp::MapField> mapField_;
  std::vector<Eigen::Vector3d> mapSites_;
  mutable std::vector<float> mapValues_;  // per triangle of the geometry mapValuesKey_ names
  mutable std::tuple<int, const void*, int> mapValuesKey_{-1, nullptr, -1};
  QString shownTitle() const;
  void updateToolTip();
  bool autoRange_ = true;
  double lo_ = 0, hi_ = 1;  // manual range
  double dataLo_ = 0, dataHi_ = 1;
  std::optional<DisplaySettings::Camera> pendingPose_;
  std::vector<SiteMarker> markers_;
  struct DrawnMarker {
    int number;
    QPointF centre;  // widget pixels, as last painted on screen
    double radius;
  };
  mutable std::vector<DrawnMarker> drawnMarkers_;  // the discs on screen, for clicks
  bool sectionOn_ = false, sectionFlip_ = false, sectionKeepPositive_ = true, outlines_ = true;
  bool mesh_ = false;
  bool glyphs_ = false;
  int sectionAxis_ = 0;
  double sectionFraction_ = 0.5;

  SnapshotBuffers buffers_;
  bool buffersDirty_ = true;
  GlRenderer renderer_;
  QString glError_;
  mutable Picker picker_;
  mutable bool pickerDirty_ = true;
  mutable int pickerGeneration_ = -1;
  int highlight_ = -1;

  Drag drag_ = Drag::None;
  QPoint pressPos_, lastPos_;
  bool moved_ = false;
  double requestedDepth_ = 0, dragStartDepth_ = 0;
  QTimer depthTimer_;
  double pendingDepth_ = -1;
  double targetDepth_ = -1;
  bool awaitingSnapshot_ = false;  // a depth request has left and its equilibrium is not back
  int frames_ = 0;
  QString lastPath_;
  QString placeholder_;
};

/// A picture of `window` with the 3D view drawn in: QWidget::grab leaves out what the view
/// paints with QPainter over its OpenGL content (the colour bar, the probe read-out).
QImage grabWindowWithView(QWidget* window, TissueView* view);

}  // namespace tp::gui
