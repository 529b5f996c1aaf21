#version 430 core
// Overlay: triangles in pixels (origin top left) with an sRGB colour each.
layout(location = 0) in vec2 aPixel;
layout(location = 1) in vec4 aColor;
uniform vec2 uSize;
out vec4 vColor;
void main() {
  vColor = aColor;
  gl_Position = vec4(aPixel.x / uSize.x * 2.0 - 1.0, 1.0 - aPixel.y / uSize.y * 2.0, 0.0, 1.0);
}
