#version 330 core
// Headlight shading, two-sided (a wall is seen from both of its cells; the section plane is a
// clip distance in the vertex shader), hatching on the clamped base and the hovered cell's walls
// highlighted.
in vec3 worldPosition;
in vec3 worldNormal;
in vec3 baseColor;
flat in vec2 wallCells;
flat in int wallFlags;

uniform vec3 eye;               // µm
uniform float highlightCell;    // dense cell index, -1 = none
uniform bool uniformColorEnabled;
uniform vec4 uniformColor;      // the probe: RGBA

out vec4 fragColor;

const int kClamped = 1;

void main() {
  vec3 n = normalize(worldNormal);
  vec3 v = normalize(eye - worldPosition);
  if (dot(n, v) < 0.0) n = -n;
  float diffuse = max(dot(n, v), 0.0);
  vec3 c = baseColor;
  float alpha = 1.0;
  float specular = 0.0;
  if (uniformColorEnabled) {
    c = uniformColor.rgb;
    alpha = uniformColor.a;
    specular = 0.45 * pow(diffuse, 48.0);  // light from the eye: the half vector is v
  } else {
    // Clamped base: diagonal stripes, light on dark and dark on light, so they show on any colour.
    if ((wallFlags & kClamped) != 0) {
      float stripe = mod(gl_FragCoord.x + gl_FragCoord.y, 8.0);
      if (stripe < 2.0) c = mix(c, vec3(0.95), 0.6);
      else if (stripe < 4.0) c = mix(c, vec3(0.05), 0.6);
    }
    if (highlightCell >= 0.0 &&
        (abs(wallCells.x - highlightCell) < 0.5 || abs(wallCells.y - highlightCell) < 0.5))
      c = mix(c, vec3(1.0, 0.5, 0.05), 0.5);
  }
  fragColor = vec4(c * (0.35 + 0.65 * diffuse) + vec3(specular), alpha);
}
