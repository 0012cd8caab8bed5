#include "GlRenderer.h"

#include <QMatrix4x4>

#include "Resources.h"

namespace tp::gui {

namespace {

#ifndef GL_PROGRAM_POINT_SIZE
constexpr GLenum GL_PROGRAM_POINT_SIZE = 0x8642;
#endif

QMatrix4x4 toQt(const Eigen::Matrix4f& m) {
  // QMatrix4x4(const float*) reads row-major values.
  const Eigen::Matrix<float, 4, 4, Eigen::RowMajor> r = m;
  return QMatrix4x4(r.data());
}

std::unique_ptr<QOpenGLShaderProgram> program(const QString& vert, const QString& frag,
                                              QString* error) {
  auto p = std::make_unique<QOpenGLShaderProgram>();
  for (const auto& [type, name] :
       {std::pair{QOpenGLShader::Vertex, vert}, std::pair{QOpenGLShader::Fragment, frag}}) {
    const QString src = shaderSource(name, error);
    if (src.isEmpty()) return nullptr;
    if (!p->addShaderFromSourceCode(type, src)) {
      if (error) *error = name + ": " + p->log();
      return nullptr;
    }
  }
  if (!p->link()) {
    if (error) *error = vert + " + " + frag + ": " + p->log();
    return nullptr;
  }
  return p;
}

}  // namespace

GlRenderer::GlRenderer()
    : wallVbo_(QOpenGLBuffer::VertexBuffer),
      lineVbo_(QOpenGLBuffer::VertexBuffer),
      pointVbo_(QOpenGLBuffer::VertexBuffer),
      sphereVbo_(QOpenGLBuffer::VertexBuffer),
      stemVbo_(QOpenGLBuffer::VertexBuffer) {}

GlRenderer::~GlRenderer() = default;

bool GlRenderer::initialize(QString* error) {
  initializeOpenGLFunctions();
  walls_ = program("tissue.vert", "tissue.frag", error);
  lines_ = program("lines.vert", "lines.frag", error);
  if (!walls_ || !lines_) return false;

  const GLsizei stride = SnapshotBuffers::kTriangleStride * sizeof(float);
  auto offset = [](int floats) { return reinterpret_cast<const void*>(floats * sizeof(float)); };
  // Walls: position, normal, colour, cells, flags.
  wallVao_.create();
  wallVao_.bind();
  wallVbo_.create();
  wallVbo_.setUsagePattern(QOpenGLBuffer::DynamicDraw);
  wallVbo_.bind();
  const int sizes[5] = {3, 3, 3, 2, 1};
  const int offsets[5] = {SnapshotBuffers::kPositionOffset, SnapshotBuffers::kNormalOffset,
                          SnapshotBuffers::kColorOffset, SnapshotBuffers::kCellsOffset,
                          SnapshotBuffers::kFlagsOffset};
  for (GLuint a = 0; a < 5; ++a) {
    glEnableVertexAttribArray(a);
    glVertexAttribPointer(a, sizes[a], GL_FLOAT, GL_FALSE, stride, offset(offsets[a]));
  }
  wallVao_.release();

  // Position-only arrays: outlines, clamped vertices, the probe's stem.
  for (auto [vao, vbo] : {std::pair{&lineVao_, &lineVbo_}, std::pair{&meshVao_, &meshVbo_},
                          std::pair{&pointVao_, &pointVbo_}, std::pair{&stemVao_, &stemVbo_},
                          std::pair{&glyphVao_, &glyphVbo_},
                          std::pair{&contactVao_, &contactVbo_}}) {
    vao->create();
    vao->bind();
    vbo->create();
    vbo->setUsagePattern(QOpenGLBuffer::DynamicDraw);
    vbo->bind();
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float), nullptr);
    vao->release();
  }

  // The probe: a unit sphere (position = normal), scaled and placed by the model matrix.
  const std::vector<float> sphere = unitSphereMesh(3);
  sphereVertices_ = static_cast<int>(sphere.size() / 6);
  sphereVao_.create();
  sphereVao_.bind();
  sphereVbo_.create();
  sphereVbo_.bind();
  sphereVbo_.allocate(sphere.data(), static_cast<int>(sphere.size() * sizeof(float)));
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 6 * sizeof(float), offset(3));
  sphereVao_.release();
  initialized_ = true;
  return true;
}

void GlRenderer::release() {
  if (!initialized_) return;
  for (auto* b : {&wallVbo_, &lineVbo_, &meshVbo_, &pointVbo_, &sphereVbo_, &stemVbo_,
                  &contactVbo_, &glyphVbo_})
    b->destroy();
  for (auto* v : {&wallVao_, &lineVao_, &meshVao_, &pointVao_, &sphereVao_, &stemVao_,
                  &contactVao_, &glyphVao_})
    v->destroy();
  walls_.reset();
  lines_.reset();
  wallVertices_ = lineVertices_ = meshVertices_ = pointVertices_ = outerWallVertices_ =
      outerLineVertices_ = outerMeshVertices_ = glyphVertices_ = outerGlyphVertices_ =
          contactVertices_ = 0;
  initialized_ = false;
}

void GlRenderer::upload(const SnapshotBuffers& b) {
  if (!initialized_) return;
  auto put = [](QOpenGLBuffer& vbo, const std::vector<float>& data) {
    vbo.bind();
    vbo.allocate(data.data(), static_cast<int>(data.size() * sizeof(float)));
    vbo.release();
  };
  put(wallVbo_, b.triangleVertices());
  put(lineVbo_, b.lineVertices());
  put(meshVbo_, b.meshVertices());
  meshVertices_ = b.meshVertexCount();
  outerMeshVertices_ = b.outerMeshVertexCount();
  put(glyphVbo_, b.glyphVertices());
  glyphVertices_ = b.glyphVertexCount();
  outerGlyphVertices_ = b.outerGlyphVertexCount();
  put(contactVbo_, b.contactVertices());
  contactVertices_ = b.contactVertexCount();
  put(pointVbo_, b.clampedPoints());
  wallVertices_ = b.triangleVertexCount();
  lineVertices_ = b.lineVertexCount();
  outerWallVertices_ = b.outerTriangleVertexCount();
  outerLineVertices_ = b.outerLineVertexCount();
  pointVertices_ = b.clampedPointCount();
}

void GlRenderer::render(const Frame& f, const QSize& pixels) {
  // QPainter may have drawn an overlay since the last frame: restore what the draws assume.
  glViewport(0, 0, pixels.width(), pixels.height());
  glDisable(GL_SCISSOR_TEST);
  glDisable(GL_STENCIL_TEST);
  glDepthMask(GL_TRUE);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glClearColor(f.background.x(), f.background.y(), f.background.z(), 1.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  if (!initialized_) return;
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  const QMatrix4x4 vp = toQt(f.viewProjection);
  const QVector4D clip = f.clip ? QVector4D(float(f.clip->normal.x()), float(f.clip->normal.y()),
                                            float(f.clip->normal.z()), float(f.clip->offset))
                                : QVector4D();

  walls_->bind();
  walls_->setUniformValue("viewProjection", vp);
  walls_->setUniformValue("model", QMatrix4x4());
  walls_->setUniformValue("eye", QVector3D(f.eye.x(), f.eye.y(), f.eye.z()));
  walls_->setUniformValue("clipEnabled", f.clip.has_value());
  walls_->setUniformValue("clipPlane", clip);
  walls_->setUniformValue("highlightCell", float(f.highlightCell));
  walls_->setUniformValue("uniformColorEnabled", false);
  // Push the walls back a little so that their outlines win the depth test.
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(1.0f, 1.0f);
  wallVao_.bind();
  // Without a cut only the outer surface can be seen: skip the inner walls behind it. The cut is
  // a hardware clip distance (not a discard), so hidden fragments fail the depth test early.
  if (f.clip) glEnable(GL_CLIP_DISTANCE0);
  glDrawArrays(GL_TRIANGLES, 0, f.clip ? wallVertices_ : outerWallVertices_);
  wallVao_.release();
  glDisable(GL_POLYGON_OFFSET_FILL);

  lines_->bind();
  lines_->setUniformValue("viewProjection", vp);
  lines_->setUniformValue("clipEnabled", f.clip.has_value());
  lines_->setUniformValue("clipPlane", clip);
  if (f.mesh && meshVertices_ > 0) {
    lines_->setUniformValue("color", QVector4D(0.35f, 0.37f, 0.42f, 1.0f));
    meshVao_.bind();
    glDrawArrays(GL_LINES, 0, f.clip ? meshVertices_ : outerMeshVertices_);
    meshVao_.release();
  }
  if (f.glyphs && glyphVertices_ > 0) {
    lines_->setUniformValue("color", QVector4D(0.05f, 0.05f, 0.08f, 1.0f));
    glyphVao_.bind();
    glDrawArrays(GL_LINES, 0, f.clip ? glyphVertices_ : outerGlyphVertices_);
    glyphVao_.release();
  }
  if (f.outlines && lineVertices_ > 0) {
    lines_->setUniformValue("color", QVector4D(0.08f, 0.08f, 0.1f, 1.0f));
    lineVao_.bind();
    glDrawArrays(GL_LINES, 0, f.clip ? lineVertices_ : outerLineVertices_);
    lineVao_.release();
  }
  if (f.clampedPoints && pointVertices_ > 0) {
    glEnable(GL_PROGRAM_POINT_SIZE);
    lines_->setUniformValue("pointSize", 4.0f);
    lines_->setUniformValue("color", QVector4D(0.75f, 0.1f, 0.1f, 1.0f));
    pointVao_.bind();
    glDrawArrays(GL_POINTS, 0, pointVertices_);
    pointVao_.release();
  }

  if (f.probe && f.stemLength > 0) {
    const Eigen::Vector3f a = f.probeCenter - f.probeRadius * f.probeAxis;
    const Eigen::Vector3f b = f.probeCenter - (f.probeRadius + f.stemLength) * f.probeAxis;
    const float stem[6] = {a.x(), a.y(), a.z(), b.x(), b.y(), b.z()};
    stemVbo_.bind();
    stemVbo_.allocate(stem, sizeof stem);
    stemVbo_.release();
    glDisable(GL_CLIP_DISTANCE0);
    lines_->setUniformValue("clipEnabled", false);
    lines_->setUniformValue("color", QVector4D(0.25f, 0.27f, 0.32f, 1.0f));
    stemVao_.bind();
    glDrawArrays(GL_LINES, 0, 2);
    stemVao_.release();
  }

  glDisable(GL_CLIP_DISTANCE0);
  if (f.probe) {
    // Translucent so that the dent under it stays visible: front faces only, over the walls.
    walls_->bind();
    walls_->setUniformValue("clipEnabled", false);
    walls_->setUniformValue("uniformColorEnabled", true);
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glEnable(GL_BLEND);
    // Destination alpha stays 1, so screenshots are opaque.
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    sphereVao_.bind();
    glVertexAttrib3f(2, 0, 0, 0);
    glVertexAttrib2f(3, -1, -1);
    glVertexAttrib1f(4, 0);
    const auto sphere = [&](const Eigen::Vector3f& c, const QVector4D& colour) {
      QMatrix4x4 model;
      model.translate(c.x(), c.y(), c.z());
      model.scale(f.probeRadius);
      walls_->setUniformValue("model", model);
      walls_->setUniformValue("uniformColor", colour);
      glDrawArrays(GL_TRIANGLES, 0, sphereVertices_);
    };
    // Where walls hide the probe (deep in a dimple, or a magnified one), a faint ghost of it
    // shows through them, so the contact stays in view: the parts behind the depth buffer only,
    // without writing depth.
    glDepthMask(GL_FALSE);
    glDepthFunc(GL_GREATER);
    sphere(f.probeCenter, QVector4D(0.92f, 0.94f, 1.0f, 0.5f));
    glDepthFunc(GL_LEQUAL);
    // The probe itself writes no depth either, so that the contact patch drawn next shows
    // through it (the walls' depth still hides the patch where they are in front of it).
    sphere(f.probeCenter, QVector4D(0.78f, 0.8f, 0.86f, 0.7f));
    if (f.targetCenter && (*f.targetCenter - f.probeCenter).norm() > 1e-3f * f.probeRadius)
      sphere(*f.targetCenter, QVector4D(0.95f, 0.7f, 0.2f, 0.35f));
    glDepthMask(GL_TRUE);
    sphereVao_.release();
    glDisable(GL_BLEND);
    glDisable(GL_CULL_FACE);
    walls_->release();
    // The contact patch: the outline of the triangles the probe presses, over the probe.
    if (contactVertices_ > 0) {
      lines_->bind();
      lines_->setUniformValue("clipEnabled", false);
      lines_->setUniformValue("color", QVector4D(kContactColour[0], kContactColour[1],
                                                 kContactColour[2], 1.0f));
      contactVao_.bind();
      glDrawArrays(GL_LINES, 0, contactVertices_);
      contactVao_.release();
      lines_->release();
    }
    return;
  }
  walls_->release();
}

}  // namespace tp::gui
