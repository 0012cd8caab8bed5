#version 330 core
// A single colour (the section plane clips in the vertex shader).
in vec3 worldPosition;

uniform vec4 color;

out vec4 fragColor;

void main() {
  fragColor = color;
}
