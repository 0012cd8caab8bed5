#pragma once
// The thin OpenGL layer: compiles the shaders, uploads the arrays SnapshotBuffers made and draws
// a frame (walls, outlines, clamped vertices, probe). Needs a current OpenGL 3.3 core context;
// owned by TissueView, which calls release() before its context goes away.

#include <QOpenGLBuffer>
#include <QOpenGLExtraFunctions>
#include <QOpenGLShaderProgram>
#include <QOpenGLVertexArrayObject>
#include <QSize>
#include <QString>

#include <Eigen/Core>
#include <memory>
#include <optional>

#include "Picking.h"
#include "SnapshotBuffers.h"

namespace tp::gui {

class GlRenderer : protected QOpenGLExtraFunctions {
 public:
  /// The contact patch's outline colour (RGB): magenta, apart from every colour map's colours.
  static constexpr float kContactColour[3] = {0.95f, 0.1f, 0.8f};

  struct Frame {
    Eigen::Matrix4f viewProjection = Eigen::Matrix4f::Identity();
    Eigen::Vector3f eye = Eigen::Vector3f::Zero();  // µm
    std::optional<ClipPlane> clip;
    int highlightCell = -1;
    bool outlines = true;
    bool mesh = false;  // every triangle edge: where the mesh is refined
    bool glyphs = false;  // principal-stress directions
    bool clampedPoints = true;
    bool probe = false;
    Eigen::Vector3f probeCenter = Eigen::Vector3f::Zero();  // µm
    float probeRadius = 1;                                  // µm
    Eigen::Vector3f probeAxis = -Eigen::Vector3f::UnitZ();  // unit, into the tissue
    // Where a probe drag has asked the probe to be, ahead of the last equilibrium (µm): drawn
    // fainter, at once, while the solver catches up.
    std::optional<Eigen::Vector3f> targetCenter;
    float stemLength = 0;                                   // µm, 0 = no stem
    Eigen::Vector3f background = Eigen::Vector3f(0.97f, 0.97f, 0.98f);
  };

  GlRenderer();
  ~GlRenderer();
  /// Compiles the shaders and creates the buffers; false (with a message) on failure.
  bool initialize(QString* error);
  bool initialized() const { return initialized_; }
  /// Frees every GL object (the context must be current).
  void release();
  void upload(const SnapshotBuffers& buffers);
  /// Draws into the bound framebuffer of `pixels` size.
  void render(const Frame& frame, const QSize& pixels);

 private:
  bool initialized_ = false;
  std::unique_ptr<QOpenGLShaderProgram> walls_, lines_;
  QOpenGLVertexArrayObject wallVao_, lineVao_, meshVao_, pointVao_, sphereVao_, stemVao_, glyphVao_,
      contactVao_;
  QOpenGLBuffer wallVbo_, lineVbo_, meshVbo_, pointVbo_, sphereVbo_, stemVbo_, glyphVbo_,
      contactVbo_;
  int glyphVertices_ = 0, outerGlyphVertices_ = 0, contactVertices_ = 0;
  int wallVertices_ = 0, lineVertices_ = 0, meshVertices_ = 0, pointVertices_ = 0,
      sphereVertices_ = 0;
  // The leading parts seen without a cut.
  int outerWallVertices_ = 0, outerLineVertices_ = 0, outerMeshVertices_ = 0;
};

}  // namespace tp::gui
