#version 330 core
// Wall outlines (GL_LINES) and clamped vertices (GL_POINTS): positions in µm.
layout(location = 0) in vec3 position;

uniform mat4 viewProjection;
uniform float pointSize;  // pixels
uniform bool clipEnabled;
uniform vec4 clipPlane;   // the section: keeps the points with dot(n, x) + d >= 0

out vec3 worldPosition;

void main() {
  worldPosition = position;
  gl_PointSize = pointSize;
  gl_Position = viewProjection * vec4(position, 1.0);
  gl_ClipDistance[0] = clipEnabled ? dot(clipPlane.xyz, position) + clipPlane.w : 1.0;
}
