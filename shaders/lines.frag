#version 330 core
// A single colour, clipped by the section plane like the walls.
in vec3 worldPosition;

uniform bool clipEnabled;
uniform vec4 clipPlane;
uniform vec4 color;

out vec4 fragColor;

void main() {
  if (clipEnabled && dot(clipPlane.xyz, worldPosition) + clipPlane.w < 0.0) discard;
  fragColor = color;
}
