#pragma once
// The compiled-in resources (shaders, icons) and the OpenGL format the application asks for.

#include <QString>
#include <QSurfaceFormat>

namespace tp::gui {

/// Registers the resources of the static library tp_gui (idempotent).
void initResources();
/// GLSL source of shaders/<name>, from the resources or the source tree; empty on failure.
QString shaderSource(const QString& name, QString* error = nullptr);
/// OpenGL 3.3 core profile with a depth buffer and `samples` samples per pixel.
QSurfaceFormat surfaceFormat(int samples);
/// Must be called before the QApplication is created. Also leaveTheSolverItsCores().
void setDefaultSurfaceFormat();
/// A software OpenGL renderer (Mesa llvmpipe) draws on the cores the simulation's worker leaves
/// (one), unless LP_NUM_THREADS is set. Before the first OpenGL context.
void leaveTheSolverItsCores();

}  // namespace tp::gui
