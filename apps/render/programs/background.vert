#version 430 core
// A full-screen triangle from gl_VertexID, shaded with a vertical gradient (sRGB).
out float vT;
void main() {
  vec2 p = vec2((gl_VertexID == 1) ? 3.0 : -1.0, (gl_VertexID == 2) ? 3.0 : -1.0);
  vT = p.y * 0.5 + 0.5;
  gl_Position = vec4(p, 0.0, 1.0);
}
