#include "Resources.h"

#include <QFile>
#include <QSurfaceFormat>

// Q_INIT_RESOURCE declares a function in the current namespace: call it from the global one.
static void initTissueProbeResources() {
  Q_INIT_RESOURCE(tissueprobe);
}

namespace tp::gui {

void initResources() {
  static const bool once = (initTissueProbeResources(), true);
  (void)once;
}

QString shaderSource(const QString& name, QString* error) {
  initResources();
  // Compiled-in copy first; the source tree as a fallback (e.g. while editing a shader).
  for (const QString& path :
       {QStringLiteral(":/shaders/") + name, QStringLiteral(TP_SOURCE_DIR "/shaders/") + name}) {
    QFile f(path);
    if (f.open(QIODevice::ReadOnly | QIODevice::Text)) return QString::fromUtf8(f.readAll());
  }
  if (error)
    *error = QStringLiteral("shader %1 not found in the resources or in %2/shaders")
                 .arg(name, QStringLiteral(TP_SOURCE_DIR));
  return {};
}

QSurfaceFormat surfaceFormat(int samples) {
  // OpenGL 3.3 core (GLSL 330) with a depth buffer for the walls.
  QSurfaceFormat f;
  f.setRenderableType(QSurfaceFormat::OpenGL);
  f.setVersion(3, 3);
  f.setProfile(QSurfaceFormat::CoreProfile);
  f.setDepthBufferSize(24);
  f.setSamples(samples);
  return f;
}

void setDefaultSurfaceFormat() {
  // No multisampling for the window itself: Qt composes the whole window with OpenGL whenever a
  // widget repaints, and a multisampled window makes every such composition (a progress bar's
  // animation, a spin box) several times dearer, which a software renderer pays in CPU time
  // taken from the solver. The 3D view asks for its own multisampling (TissueView).
  QSurfaceFormat::setDefaultFormat(surfaceFormat(0));
}

}  // namespace tp::gui
