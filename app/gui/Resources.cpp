#include "Resources.h"

#include <QFile>
#include <QSurfaceFormat>
#include <QtGlobal>

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
  // taken from the solver. The 3D view has none either (TissueView); exported images do.
  QSurfaceFormat::setDefaultFormat(surfaceFormat(0));
  leaveTheSolverItsCores();
}

void leaveTheSolverItsCores() {
  // Mesa's software renderer (llvmpipe: under Xvfb, over remote X, on machines without a GPU
  // driver) rasterises on one thread per core unless LP_NUM_THREADS says otherwise, while the
  // simulation's worker solves on all cores but one (SimulationWorker::processNext): the
  // drawing gets the core that is left. On the 2-core test VM, a probe drag under Xvfb
  // (TP_GUI_MEASURE=1 tests/gui/with-display.sh build/bin/test_gui_window
  // dragRatesOnTheDefaultMeristem, eight runs alternated with llvmpipe's default of two threads)
  // went from a median of 7.4 to 8.0 equilibria/s, faster in 7 of the 8 pairs, at the same
  // frame rate (38–49 frames/s either way). Read when llvmpipe starts (the first OpenGL
  // context); GPU drivers ignore it; a value the user set is kept.
  if (!qEnvironmentVariableIsSet("LP_NUM_THREADS")) qputenv("LP_NUM_THREADS", "1");
}

}  // namespace tp::gui
