#include "TissueView.h"

#include <QFontMetricsF>
#include <QLineF>
#include <QKeyEvent>
#include <QMouseEvent>
#include <QOpenGLContext>
#include <QOpenGLFramebufferObject>
#include <QPainter>
#include <QWheelEvent>

#include <algorithm>
#include <cmath>
#include <limits>

#include "ColorBar.h"
#include "Curves.h"
#include "MapValues.h"
#include "Resources.h"

namespace tp::gui {

namespace {

Eigen::AlignedBox3d boundsOf(const std::vector<float>& x) {
  Eigen::AlignedBox3d b;
  for (size_t i = 0; i + 2 < x.size(); i += 3) b.extend(Eigen::Vector3d(x[i], x[i + 1], x[i + 2]));
  return b;
}

}  // namespace

TissueView::TissueView(QWidget* parent) : QOpenGLWidget(parent) {
  setObjectName("tissueView");
  setFocusPolicy(Qt::StrongFocus);
  setMouseTracking(true);  // hover highlight without a button pressed
  setMinimumSize(320, 240);
  setFormat(surfaceFormat(0));  // no multisampling: with a software renderer it cost the solver CPU
  // A fallback only: depth requests are paced by the equilibria coming back (setSnapshot), and
  // this sends the pending one should a request bring no snapshot.
  depthTimer_.setSingleShot(true);
  depthTimer_.setInterval(300);
  connect(&depthTimer_, &QTimer::timeout, this, [this] {
    awaitingSnapshot_ = false;
    sendPendingDepth();
  });
  updateToolTip();
}

void TissueView::updateToolTip() {
  setToolTip(
      tr("Left drag: turn · Shift+left or middle drag: pan · Wheel: zoom\n"
         "%1 · Right or Ctrl+left drag: probe depth\n"
         "Keys: arrows turn, +/- zoom, F fit, 1/3/7 front/right/top, R reset, "
         "Z zoom to the probe")
          .arg(mapValue_ >= 0 ? tr("Click a map site (dot): its curve")
                              : tr("Click on the surface: indentation site")));
}

TissueView::~TissueView() {
  // QOpenGLWidget's destructor destroys the context after this one has run, and the context's
  // aboutToBeDestroyed would then call releaseGL on a half-destroyed TissueView (UBSan, issue 9).
  if (QOpenGLContext* c = context()) disconnect(c, nullptr, this, nullptr);
  releaseGL();
}

void TissueView::releaseGL() {
  // hellogl2's cleanup: the GL objects belong to this widget's context, which must be current.
  if (!renderer_.initialized() || !context()) return;
  makeCurrent();
  renderer_.release();
  doneCurrent();
}

void TissueView::initializeGL() {
  connect(context(), &QOpenGLContext::aboutToBeDestroyed, this, &TissueView::releaseGL,
          Qt::UniqueConnection);
  glError_.clear();
  if (!renderer_.initialize(&glError_)) qWarning("TissueProbe: OpenGL: %s", qPrintable(glError_));
  buffersDirty_ = true;
}

void TissueView::resizeGL(int w, int h) {
  camera_.setViewport(w, h);
}

double TissueView::sectionPosition() const {
  const Eigen::AlignedBox3d b = boundsOf(snapshot_.positions);
  return b.min()[sectionAxis_] + sectionFraction_ * b.diagonal()[sectionAxis_];
}

std::optional<ClipPlane> TissueView::clipPlane() const {
  if (!sectionOn_ || snapshot_.empty()) return std::nullopt;
  const double c = sectionPosition();
  const Eigen::Vector3d e = Eigen::Vector3d::Unit(sectionAxis_);
  ClipPlane p;  // keeps n·x + d ≥ 0
  p.normal = sectionKeepPositive_ ? e : Eigen::Vector3d(-e);
  p.offset = sectionKeepPositive_ ? -c : c;
  return p;
}

void TissueView::setOverlayScale(double scale) {
  overlayScale_ = std::clamp(scale, 1.0, 3.0);
  update();
}

void TissueView::setDeformationScale(double scale) {
  scale = std::clamp(scale, 1.0, 50.0);
  if (scale == deformationScale_) return;
  deformationScale_ = scale;
  applyDeformationScale();
  buffersDirty_ = true;
  pickerDirty_ = true;
  update();
}

// x_shown = x_turgid + s (x − x_turgid); the probe's centre moves s times its depth, so it sits
// in the magnified dimple. The depth, the force and the fields stay those of the source.
void TissueView::applyDeformationScale() {
  snapshot_ = source_;
  const double s = deformationScale_;
  if (s == 1.0 || source_.turgidPositions.size() != source_.positions.size()) return;
  for (size_t i = 0; i < snapshot_.positions.size(); ++i)
    snapshot_.positions[i] = float(source_.turgidPositions[i] +
                                   s * (source_.positions[i] - source_.turgidPositions[i]));
  snapshot_.contactCenter = source_.contactCenter + (s - 1.0) * source_.depth * source_.axis;
}

namespace {
Eigen::Quaterniond quaternionOf(const Eigen::Vector4d& wxyz) {
  return Eigen::Quaterniond(wxyz[0], wxyz[1], wxyz[2], wxyz[3]);
}
}  // namespace

DisplaySettings::Camera TissueView::cameraPose() const {
  DisplaySettings::Camera pose;
  pose.target = camera_.target();
  const Eigen::Quaterniond& q = camera_.orientation();
  pose.orientation = Eigen::Vector4d(q.w(), q.x(), q.y(), q.z());
  pose.distance = camera_.distance();
  return pose;
}

void TissueView::setCameraPose(const DisplaySettings::Camera& pose) {
  camera_.setPose(pose.target, quaternionOf(pose.orientation), pose.distance);
  pendingPose_ = pose;
  update();
}

void TissueView::setSnapshot(const Snapshot& s) {
  const bool newTissue = !s.empty() && (snapshot_.empty() || s.phase == Snapshot::Phase::Rest ||
                                        QString::fromStdString(s.geometry->path) != lastPath_);
  source_ = s;
  applyDeformationScale();
  awaitingSnapshot_ = false;
  if (drag_ == Drag::Depth) sendPendingDepth();  // the solver is free: the newest depth
  if (!s.probeVisible || std::abs(s.depth - targetDepth_) < 1e-6)
    targetDepth_ = -1;
  buffersDirty_ = true;
  pickerDirty_ = true;
  if (!s.empty()) {
    lastPath_ = QString::fromStdString(s.geometry->path);
    Eigen::AlignedBox3d b = boundsOf(snapshot_.positions);
    if (s.probeVisible) {
      const Eigen::Vector3d c = snapshot_.probeCenter();
      b.extend(c + Eigen::Vector3d::Constant(s.probeRadius));
      b.extend(c - Eigen::Vector3d::Constant(s.probeRadius));
    }
    camera_.setSceneBounds(b);
    if (newTissue && pendingPose_) {
      camera_.setPose(pendingPose_->target, quaternionOf(pendingPose_->orientation),
                      pendingPose_->distance);
      pendingPose_.reset();
    } else if (newTissue) {
      camera_.reset();
    }
  }
  updateRange();
  update();
}

void TissueView::sendPendingDepth() {
  if (pendingDepth_ < 0) return;
  awaitingSnapshot_ = true;
  depthTimer_.start();
  const double depth = pendingDepth_;
  pendingDepth_ = -1;
  emit depthRequested(depth);
}

void TissueView::clearTarget() {
  if (targetDepth_ < 0) return;
  targetDepth_ = -1;
  update();
}

const std::vector<float>& TissueView::shownValues() const {
  static const std::vector<float> none;
  if (snapshot_.empty()) return none;
  if (mapValue_ < 0) return snapshot_.fields[int(field_)];
  // The map at each outer triangle's rest centroid (Shepard's interpolation of the sites), once
  // per geometry, map and value.
  const TissueGeometry& g = *snapshot_.geometry;
  const auto key = std::make_tuple(g.generation, static_cast<const void*>(mapField_.get()), mapValue_);
  if (key != mapValuesKey_) {
    mapValuesKey_ = key;
    mapValues_.assign(g.triangleCount(), std::numeric_limits<float>::quiet_NaN());
    if (mapField_)
      for (int t = 0; t < g.triangleCount(); ++t) {
        if (!g.outer[t]) continue;
        Eigen::Vector3d c = Eigen::Vector3d::Zero();
        for (int k = 0; k < 3; ++k) {
          const std::uint32_t v = g.triangles[3 * t + k];
          c += Eigen::Vector3d(g.rest[3 * v], g.rest[3 * v + 1], g.rest[3 * v + 2]) / 3.0;
        }
        mapValues_[t] = float(mapField_->interpolated(c, MapField::Value(mapValue_)));
      }
  }
  return mapValues_;
}

QString TissueView::shownTitle() const {
  if (mapValue_ >= 0)
    return QStringLiteral("%1 (%2)").arg(QString::fromUtf8(mapValueInfo(mapValue_).name),
                                         QString::fromUtf8(mapValueInfo(mapValue_).unit));
  return QStringLiteral("%1 (%2)").arg(QString::fromUtf8(fieldName(field_)),
                                       QString::fromUtf8(fieldUnit(field_)));
}

void TissueView::setMap(std::shared_ptr<const MapField> map, std::vector<Eigen::Vector3d> sites) {
  mapField_ = std::move(map);
  mapSites_ = std::move(sites);
  if (mapValue_ >= 0) {
    buffersDirty_ = true;
    updateRange();
  }
  update();
}

void TissueView::setMapValue(int v) {
  v = v >= 0 && v < MapField::kValueCount ? v : -1;
  if (v == mapValue_) return;
  mapValue_ = v;
  updateToolTip();
  buffersDirty_ = true;
  updateRange();
  update();
}

void TissueView::updateRange() {
  const double oldLo = map_.lo(), oldHi = map_.hi();
  if (!snapshot_.empty()) {
    const bool diverging = map_.diverging() || (mapValue_ < 0 && quantityInfo(field_).change);
    const AutoRange r = mapValue_ >= 0 ? tp::gui::autoRange(shownValues(), false, diverging)
                                       : tp::gui::autoRange(snapshot_, field_, diverging);
    dataLo_ = r.dataLo;
    dataHi_ = r.dataHi;
    if (autoRange_) map_.setRange(r.lo, r.hi);
  }
  if (!autoRange_) {
    map_.setRange(lo_, hi_);
  }
  if (map_.lo() != oldLo || map_.hi() != oldHi) {
    buffersDirty_ = true;
    emit rangeChanged(map_.lo(), map_.hi());
  }
}

void TissueView::setField(Field field) {
  if (field == field_) return;
  field_ = field;
  buffersDirty_ = true;
  updateRange();
  update();
}

void TissueView::setColorMapKind(ColorMap::Kind kind) {
  if (kind == map_.kind()) return;
  map_.setKind(kind);
  buffersDirty_ = true;
  updateRange();
  update();
}

void TissueView::setAutoRange(bool on) {
  if (on == autoRange_) return;
  autoRange_ = on;
  if (!on) lo_ = map_.lo(), hi_ = map_.hi();  // start from what is shown
  updateRange();
  update();
}

void TissueView::setRange(double lo, double hi) {
  if (lo == lo_ && hi == hi_) return;
  lo_ = lo;
  hi_ = hi;
  if (autoRange_) return;
  updateRange();
  update();
}

void TissueView::setSection(bool enabled, int axis, double fraction, bool flip) {
  axis = std::clamp(axis, 0, 2);
  fraction = std::clamp(fraction, 0.0, 1.0);
  if (enabled == sectionOn_ && axis == sectionAxis_ && fraction == sectionFraction_ &&
      flip == sectionFlip_)
    return;
  sectionOn_ = enabled;
  sectionAxis_ = axis;
  sectionFraction_ = fraction;
  sectionFlip_ = flip;
  // Keep the half away from the viewer, so that the cut faces the camera (flip: the other half).
  // Decided here, not per frame, so that turning the tissue does not swap the halves.
  if (!snapshot_.empty()) sectionKeepPositive_ = (camera_.eye()[axis] < sectionPosition()) != flip;
  update();
}

void TissueView::setPlaceholder(const QString& text) {
  if (text == placeholder_) return;
  placeholder_ = text;
  update();
}

void TissueView::setOutlinesVisible(bool on) {
  if (on == outlines_) return;
  outlines_ = on;
  update();
}

void TissueView::setMeshVisible(bool on) {
  if (on == mesh_) return;
  mesh_ = on;
  update();
}

void TissueView::setGlyphsVisible(bool on) {
  if (on == glyphs_) return;
  glyphs_ = on;
  update();
}

void TissueView::setRotationMode(Camera::RotationMode mode) {
  camera_.setRotationMode(mode);
}

void TissueView::fitToView() {
  camera_.fitToScene();
  update();
}

void TissueView::setStandardView(Camera::StandardView view) {
  camera_.setStandardView(view);
  update();
}

void TissueView::zoomToProbe() {
  if (!snapshot_.probeVisible) return;
  // The probe's cell and its neighbours: a box of about three cells around the probe.
  const double cell = snapshot_.geometry->meanCellSize;
  const double r = std::max(4.0 * snapshot_.probeRadius, 1.5 * (cell > 0 ? cell : 1.0));
  const Eigen::Vector3d c = snapshot_.probeCenter();
  // Seen from the probe's side, 40° off its axis, so that neither the tissue nor the probe
  // hides the contact and the dimple shows in relief; on the side the camera already faces.
  const Eigen::Vector3d axis = snapshot_.axis.normalized();
  Eigen::Vector3d side = camera_.viewDirection() - camera_.viewDirection().dot(axis) * axis;
  if (side.norm() < 1e-6) side = axis.unitOrthogonal();
  camera_.lookAlong(std::cos(40.0 * M_PI / 180) * axis + std::sin(40.0 * M_PI / 180) * side.normalized());
  // The box holds the probe where it is drawn and where it truly is (they differ by the
  // deformation scale): the magnified dimple and the surface around it both in view.
  Eigen::AlignedBox3d box(c - Eigen::Vector3d::Constant(r), c + Eigen::Vector3d::Constant(r));
  box.extend(source_.probeCenter() + Eigen::Vector3d::Constant(r));
  box.extend(source_.probeCenter() - Eigen::Vector3d::Constant(r));
  camera_.fit(box);
  update();
}

void TissueView::resetView() {
  camera_.reset();
  update();
}

void TissueView::ensurePicker() const {
  if (snapshot_.empty()) return;
  if (pickerGeneration_ != snapshot_.geometry->generation) {
    picker_.build(snapshot_.geometry->triangles, snapshot_.positions);
    pickerGeneration_ = snapshot_.geometry->generation;
  } else if (pickerDirty_) {
    picker_.update(snapshot_.positions);
  }
  pickerDirty_ = false;
}

std::optional<Hit> TissueView::pickAt(const QPoint& pixel) const {
  if (snapshot_.empty()) return std::nullopt;
  ensurePicker();
  Camera cam = camera_;
  cam.setViewport(width(), height());
  return picker_.pick(cam.rayAt(pixel.x() + 0.5, pixel.y() + 0.5), {}, clipPlane());
}

void TissueView::updateHover(const QPoint& pixel) {
  const std::optional<Hit> hit = pickAt(pixel);
  const int cell = hit ? cellUnderCursor(*snapshot_.geometry, *hit) : -1;
  if (cell == highlight_) return;
  highlight_ = cell;
  QString text;
  if (cell >= 0) {
    const auto& g = *snapshot_.geometry;
    const double volume =
        cell < static_cast<int>(snapshot_.cellVolumes.size()) ? snapshot_.cellVolumes[cell] : 0;
    const auto& values = shownValues();
    text = tr("Cell %1: volume %2 µm³").arg(g.cellLabels[cell]).arg(volume, 0, 'f', 1);
    if (hit->triangle < static_cast<int>(values.size()) && std::isfinite(values[hit->triangle]))
      text += tr(" · wall %1 %2 %3")
                  .arg(QString::fromUtf8(mapValue_ >= 0 ? mapValueInfo(mapValue_).name
                                                        : fieldName(field_)))
                  .arg(values[hit->triangle], 0, 'g', 4)
                  .arg(QString::fromUtf8(mapValue_ >= 0 ? mapValueInfo(mapValue_).unit
                                                        : fieldUnit(field_)));
  }
  emit hoverChanged(text);
  update();
}

void TissueView::leaveEvent(QEvent* e) {
  if (highlight_ >= 0) {
    highlight_ = -1;
    emit hoverChanged(QString());
    update();
  }
  QOpenGLWidget::leaveEvent(e);
}

void TissueView::mousePressEvent(QMouseEvent* e) {
  pressPos_ = lastPos_ = e->position().toPoint();
  moved_ = false;
  const bool left = e->button() == Qt::LeftButton;
  const auto mods = e->modifiers();
  if (e->button() == Qt::RightButton || (left && (mods & Qt::ControlModifier))) {
    drag_ = snapshot_.probeVisible ? Drag::Depth : Drag::None;
    dragStartDepth_ = requestedDepth_;
  } else if (e->button() == Qt::MiddleButton || (left && (mods & Qt::ShiftModifier))) {
    drag_ = Drag::Pan;
  } else if (left) {
    drag_ = Drag::Rotate;
  } else {
    drag_ = Drag::None;
  }
  e->accept();
}

void TissueView::mouseMoveEvent(QMouseEvent* e) {
  const QPoint pos = e->position().toPoint();
  if (drag_ == Drag::None) {
    updateHover(pos);
    return;
  }
  if ((pos - pressPos_).manhattanLength() > 3) moved_ = true;
  switch (drag_) {
    case Drag::Rotate:
      if (moved_)
        camera_.rotate({double(lastPos_.x()), double(lastPos_.y())},
                       {double(pos.x()), double(pos.y())});
      break;
    case Drag::Pan:
      camera_.pan({double(lastPos_.x()), double(lastPos_.y())}, {double(pos.x()), double(pos.y())});
      break;
    case Drag::Depth: {
      // Down presses in: a hundred pixels per probe radius, whatever the zoom. The probe's
      // target follows the mouse at once; the tissue follows as the worker sends equilibria.
      // (Divided by the deformation scale: the probe drawn stays under the mouse.)
      const double umPerPixel = std::max(snapshot_.probeRadius, 0.1) / 100.0 / deformationScale_;
      pendingDepth_ = std::max(0.0, dragStartDepth_ + (pos.y() - pressPos_.y()) * umPerPixel);
      targetDepth_ = pendingDepth_;
      // One request at a time: the next leaves when this one's equilibrium comes back, so the
      // solver always works on the newest depth and never waits for a timer.
      if (!awaitingSnapshot_) sendPendingDepth();
      break;
    }
    case Drag::None:
      break;
  }
  lastPos_ = pos;
  update();
}

void TissueView::mouseReleaseEvent(QMouseEvent* e) {
  const QPoint pos = e->position().toPoint();
  if (drag_ == Drag::Rotate && !moved_ && e->button() == Qt::LeftButton) {
    // A click, not a drag: on a site's disc, select that site; else choose the indentation site.
    const std::optional<Hit> hit = pickAt(pos);
    const TissueGeometry* g = snapshot_.empty() ? nullptr : snapshot_.geometry.get();
    if (const int number = markerAt(pos); number > 0) {
      emit siteMarkerClicked(number);
    } else if (!hit || !g) {
      emit pickRejected(tr("No tissue under the cursor"));
    } else if (!g->outer[hit->triangle]) {
      emit pickRejected(tr("Pick a site on the outer surface (this is an inner wall)"));
    } else if (g->clampedTriangle[hit->triangle]) {
      emit pickRejected(tr("Pick a site on the free surface (this part is clamped)"));
    } else if (mapValue_ >= 0) {  // the map is shown: a click asks for a map site's curve
      Eigen::Vector3d rest = Eigen::Vector3d::Zero();
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t v = g->triangles[3 * hit->triangle + k];
        rest += hit->barycentric[k] * Eigen::Vector3d(g->rest[3 * v], g->rest[3 * v + 1], g->rest[3 * v + 2]);
      }
      emit mapPointPicked(rest);
    } else {
      emit sitePicked(g->generation, hit->triangle, hit->barycentric);
    }
  }
  if (drag_ == Drag::Depth && pendingDepth_ >= 0) {  // the drag's last depth, now
    sendPendingDepth();
    depthTimer_.stop();
    awaitingSnapshot_ = false;
  }
  drag_ = Drag::None;
  e->accept();
}

void TissueView::wheelEvent(QWheelEvent* e) {
  // One notch (120) zooms by 20 %, towards the point under the cursor.
  camera_.zoomAt({e->position().x(), e->position().y()},
                 std::pow(1.2, e->angleDelta().y() / 120.0));
  update();
  e->accept();
}

void TissueView::keyPressEvent(QKeyEvent* e) {
  switch (e->key()) {
    case Qt::Key_Left:
      camera_.rotateBy(-5, 0);
      break;
    case Qt::Key_Right:
      camera_.rotateBy(5, 0);
      break;
    case Qt::Key_Up:
      camera_.rotateBy(0, -5);
      break;
    case Qt::Key_Down:
      camera_.rotateBy(0, 5);
      break;
    case Qt::Key_Plus:
    case Qt::Key_Equal:
      camera_.zoom(1.2);
      break;
    case Qt::Key_Minus:
      camera_.zoom(1 / 1.2);
      break;
    case Qt::Key_F:
      camera_.fitToScene();
      break;
    case Qt::Key_1:
      camera_.setStandardView(Camera::StandardView::Front);
      break;
    case Qt::Key_3:
      camera_.setStandardView(Camera::StandardView::Right);
      break;
    case Qt::Key_7:
      camera_.setStandardView(Camera::StandardView::Top);
      break;
    case Qt::Key_R:
      camera_.reset();
      break;
    case Qt::Key_Z:
      zoomToProbe();
      return;
    default:
      QOpenGLWidget::keyPressEvent(e);
      return;
  }
  update();
}

GlRenderer::Frame TissueView::frame(const Camera& cam) const {
  GlRenderer::Frame f;
  f.viewProjection = cam.viewProjection().cast<float>();
  f.eye = cam.eye().cast<float>();
  f.clip = clipPlane();
  f.highlightCell = highlight_;
  f.outlines = outlines_;
  f.mesh = mesh_;
  f.glyphs = glyphs_;
  f.probe = snapshot_.probeVisible;
  f.probeCenter = snapshot_.probeCenter().cast<float>();
  f.probeRadius = float(snapshot_.probeRadius);
  f.probeAxis = snapshot_.axis.cast<float>();
  if (snapshot_.probeVisible && targetDepth_ >= 0)
    f.targetCenter = (snapshot_.probeCenter() +
                      deformationScale_ * (targetDepth_ - snapshot_.depth) * snapshot_.axis)
                         .cast<float>();
  // The probe's stem (the cantilever's direction) keeps the site visible from afar.
  const double extent =
      snapshot_.empty() ? 1.0 : 0.5 * boundsOf(snapshot_.positions).diagonal().norm();
  f.stemLength = float(std::max(6.0 * snapshot_.probeRadius, 0.15 * extent));
  return f;
}

void TissueView::setSiteMarkers(std::vector<SiteMarker> markers) {
  markers_ = std::move(markers);
  update();
}

// Each earlier site as a numbered disc; one hidden behind the tissue (or cut away by the
// section) as a faint ring, so that sites on the far side are not mistaken for near ones; the
// selected curve's site larger, ringed in yellow.
void TissueView::paintSiteMarkers(QPainter& p, const QSize& size, double scale) const {
  const bool showMap = mapValue_ >= 0 && !mapSites_.empty();
  if ((markers_.empty() && !showMap) || snapshot_.empty()) return;
  ensurePicker();
  Camera cam = camera_;
  cam.setViewport(size.width(), size.height());
  const std::optional<ClipPlane> clip = clipPlane();
  const Eigen::Vector3d eye = cam.eye();
  // Where a point on the surface is drawn, and whether the tissue (or the section) hides it.
  auto place = [&](const Eigen::Vector3d& x, QPointF* at, bool* hidden) {
    const Eigen::Vector3d px = cam.project(x);
    if (!(px.z() > -1 && px.z() < 1)) return false;  // behind the eye or beyond the far plane
    const double toSite = (x - eye).norm();
    Ray ray;
    ray.origin = eye;
    ray.direction = (x - eye) / toSite;
    const std::optional<Hit> hit = picker_.pick(ray, {}, clip);
    // The site lies on the surface it was picked on; the state shown may have moved it a little
    // (a dimple, a deformation scale): a hit within a cell's fraction in front still counts.
    const double tolerance = std::max(0.5, 0.02 * toSite) + deformationScale_ * 0.5;
    *hidden = (hit && hit->distance < toSite - tolerance) || (clip && !clip->keeps(x));
    *at = QPointF(px.x(), px.y());
    return true;
  };
  p.save();
  p.setRenderHint(QPainter::Antialiasing);
  // The map's sites: small dark dots ringed in white, the hidden ones left out.
  if (showMap) {
    p.setPen(QPen(QColor(255, 255, 255), 1.0 * scale));
    p.setBrush(QColor(30, 30, 30));
    for (const Eigen::Vector3d& x : mapSites_) {
      QPointF c;
      bool hidden = false;
      if (place(x, &c, &hidden) && !hidden) p.drawEllipse(c, 2.5 * scale, 2.5 * scale);
    }
  }
  QFont font = p.font();
  font.setPointSizeF(8.0 * scale);
  font.setBold(true);
  p.setFont(font);
  const bool onScreen = size == this->size();  // not an offscreen image: clicks can find them
  if (onScreen) drawnMarkers_.clear();
  for (const SiteMarker& m : markers_) {
    QPointF c;
    bool hidden = false;
    if (!place(m.position, &c, &hidden)) continue;
    const double r = (m.highlighted ? 10.0 : 7.5) * scale;
    QColor fill = m.colour.isValid() ? m.colour : QColor(90, 90, 90);
    if (hidden) {
      fill.setAlpha(70);
      p.setPen(QPen(fill, 1.5 * scale));
      p.setBrush(Qt::NoBrush);
    } else {
      p.setPen(QPen(m.highlighted ? QColor(255, 215, 0) : QColor(255, 255, 255),
                    (m.highlighted ? 3.0 : 1.5) * scale));
      p.setBrush(fill);
    }
    p.drawEllipse(c, r, r);
    if (onScreen && !hidden) drawnMarkers_.push_back({m.number, c, r});
    p.setPen(hidden ? fill : QColor(255, 255, 255));
    p.drawText(QRectF(c.x() - r, c.y() - r, 2 * r, 2 * r), Qt::AlignCenter,
               QString::number(m.number));
  }
  p.restore();
}

int TissueView::markerAt(const QPoint& pixel) const {
  // The last drawn on top wins (markers are painted in order).
  for (auto it = drawnMarkers_.rbegin(); it != drawnMarkers_.rend(); ++it)
    if (QLineF(it->centre, QPointF(pixel)).length() <= it->radius + 1) return it->number;
  return 0;
}

std::optional<QPointF> TissueView::markerCentre(int number) const {
  for (const DrawnMarker& m : drawnMarkers_)
    if (m.number == number) return m.centre;
  return std::nullopt;
}

void TissueView::paintOverlay(QPainter& p, const QSize& size, double scale) const {
  const QRectF area(QPointF(0, 0), QSizeF(size));
  if (!glError_.isEmpty()) {
    p.setPen(Qt::red);
    p.drawText(area.adjusted(10, 10, -10, -10), Qt::AlignLeft | Qt::TextWordWrap,
               tr("OpenGL failed: %1").arg(glError_));
    return;
  }
  if (snapshot_.empty()) {
    p.setPen(Qt::darkGray);
    p.drawText(area, Qt::AlignCenter | Qt::TextWordWrap,
               placeholder_.isEmpty() ? tr("Loading the tissue…") : placeholder_);
    return;
  }
  const QString title = shownTitle();
  paintSiteMarkers(p, size, scale);
  paintColorBar(p, area, map_, title, scale, dataLo_, dataHi_);
  if (snapshot_.probeVisible) {
    QFont font = p.font();
    font.setPointSizeF(10.0 * scale);
    p.setFont(font);
    const QString text =
               tr("depth %1 µm   force %2 µN%3%4")
                   .arg(snapshot_.depth, 0, 'f', 3)
                   .arg(QString::fromStdString(forceText(snapshot_.force)))
                   .arg(targetDepth_ >= 0 && std::abs(targetDepth_ - snapshot_.depth) > 5e-4
                            ? tr("   → %1 µm").arg(targetDepth_, 0, 'f', 3)
                            : QString())
                   .arg(deformationScale_ != 1.0
                            ? tr("\ndisplacement ×%1").arg(deformationScale_, 0, 'g', 3)
                            : QString());
    // On a light panel, as the colour bar: readable over the darkest colours of any map.
    const QFontMetricsF fm(font);
    const QRectF textRect = fm.boundingRect(QRectF(0, 0, 1e6, 1e6), Qt::AlignLeft, text)
                                .translated(10 * scale + 6 * scale, 8 * scale + 4 * scale);
    p.save();
    p.setRenderHint(QPainter::Antialiasing);
    p.setPen(QPen(QColor(0, 0, 0, 60), 1.0 * scale));
    p.setBrush(QColor(255, 255, 255, scale > 1.0 ? 255 : 230));  // opaque when presenting
    p.drawRoundedRect(textRect.adjusted(-6 * scale, -4 * scale, 6 * scale, 4 * scale), 4 * scale,
                      4 * scale);
    p.restore();
    p.setPen(scale > 1.0 ? QColor(0, 0, 0) : QColor(20, 20, 20));
    p.drawText(textRect, Qt::AlignLeft | Qt::AlignTop, text);
  }
}

void TissueView::paintGL() {
  camera_.setViewport(width(), height());
  if (buffersDirty_ && renderer_.initialized()) {
    buffers_.build(snapshot_, shownValues(), map_);
    renderer_.upload(buffers_);
    buffersDirty_ = false;
  }
  const double dpr = devicePixelRatioF();
  renderer_.render(frame(camera_), QSize(int(width() * dpr), int(height() * dpr)));
  ++frames_;
  QPainter painter(this);
  paintOverlay(painter, size(), overlayScale_);
  painter.end();
  emit frameRendered();
}

QImage TissueView::renderImage(const QSize& size) {
  QImage image;
  if (!size.isValid() || size.isEmpty()) return image;
  makeCurrent();
  if (renderer_.initialized()) {
    if (buffersDirty_) {
      buffers_.build(snapshot_, shownValues(), map_);
      renderer_.upload(buffers_);
      buffersDirty_ = false;
    }
    QOpenGLFramebufferObjectFormat format;
    format.setAttachment(QOpenGLFramebufferObject::Depth);
    format.setSamples(4);
    QOpenGLFramebufferObject fbo(size, format);
    if (fbo.isValid() && fbo.bind()) {
      Camera cam = camera_;
      cam.setViewport(size.width(), size.height());
      renderer_.render(frame(cam), size);
      image = fbo.toImage().convertToFormat(QImage::Format_RGB32);
      fbo.release();
    }
  }
  doneCurrent();
  if (image.isNull()) return image;
  QPainter painter(&image);
  paintOverlay(painter, size, overlayScale_ * double(size.height()) / std::max(1, height()));
  return image;
}

QImage grabWindowWithView(QWidget* window, TissueView* view) {
  QImage image = window->grab().toImage();
  if (view && view->isVisible() && window->isAncestorOf(view)) {
    QPainter p(&image);  // in logical coordinates: the image carries the pixel ratio
    const QImage fb = view->grabFramebuffer();
    p.drawImage(QRectF(view->mapTo(window, QPoint(0, 0)), QSizeF(view->size())), fb,
                QRectF(QPointF(0, 0), QSizeF(fb.size())));
  }
  return image;
}

}  // namespace tp::gui
