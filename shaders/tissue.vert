#version 330 core
// Walls of the tissue and the probe sphere: positions in µm (world), a normal per corner (smooth
// inside a wall, the triangle's own on its outline), a colour from the field's colour map, the
// wall's two cells (for the hover highlight) and flags.
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 color;
layout(location = 3) in vec2 cells;
layout(location = 4) in float flags;

uniform mat4 viewProjection;
uniform mat4 model;  // identity for the tissue; translation and uniform scale for the probe
uniform bool clipEnabled;
uniform vec4 clipPlane;  // the section: keeps the points with dot(n, x) + d >= 0

out vec3 worldPosition;
out vec3 worldNormal;
out vec3 baseColor;
flat out vec2 wallCells;
flat out int wallFlags;

void main() {
  vec4 world = model * vec4(position, 1.0);
  worldPosition = world.xyz;
  worldNormal = mat3(model) * normal;  // no rotation or shear in `model`: no inverse transpose
  baseColor = color;
  wallCells = cells;
  wallFlags = int(flags + 0.5);
  gl_Position = viewProjection * world;
  // A clip distance (enabled with GL_CLIP_DISTANCE0), so hidden fragments still fail the depth
  // test early, which a discard in the fragment shader would prevent.
  gl_ClipDistance[0] = clipEnabled ? dot(clipPlane.xyz, world.xyz) + clipPlane.w : 1.0;
}
