#!/bin/sh
# Runs a test that draws with OpenGL: on the current X display, or on a virtual one (Xvfb) when
# there is none. QOpenGLWidget does not work on Qt's offscreen platform.
if [ -n "${DISPLAY:-}" ]; then
  exec "$@"
fi
exec xvfb-run -a -s '-screen 0 1280x800x24' "$@"
