#version 430 core
// Per triangle: the face normal turned towards the eye (which side of the surface is seen) and, per
// vertex, its distance in pixels to the opposite edge, interpolated without perspective.
layout(triangles) in;
layout(triangle_strip, max_vertices = 3) out;
in VertexData { vec3 viewPos; vec3 viewNormal; float scalar; } vi[];
out FragData {
  vec3 viewPos; vec3 viewNormal; float scalar;
  flat vec3 seenNormal;
  noperspective vec3 edgeDist;
} go;
uniform vec2 uViewport;
void main() {
  vec3 fn = cross(vi[1].viewPos - vi[0].viewPos, vi[2].viewPos - vi[0].viewPos);
  vec3 mid = (vi[0].viewPos + vi[1].viewPos + vi[2].viewPos) / 3.0;
  if (dot(fn, -mid) < 0.0) fn = -fn;
  float fl = length(fn);
  fn = fl > 0.0 ? fn / fl : vec3(0.0, 0.0, 1.0);
  vec2 p[3];
  for (int k = 0; k < 3; ++k) p[k] = gl_in[k].gl_Position.xy / gl_in[k].gl_Position.w * 0.5 * uViewport;
  float area = abs((p[1].x - p[0].x) * (p[2].y - p[0].y) - (p[1].y - p[0].y) * (p[2].x - p[0].x));
  vec3 h = vec3(area / max(length(p[2] - p[1]), 1e-6),
                area / max(length(p[2] - p[0]), 1e-6),
                area / max(length(p[1] - p[0]), 1e-6));
  for (int k = 0; k < 3; ++k) {
    go.viewPos = vi[k].viewPos;
    go.viewNormal = vi[k].viewNormal;
    go.scalar = vi[k].scalar;
    go.seenNormal = fn;
    go.edgeDist = vec3(k == 0 ? h.x : 0.0, k == 1 ? h.y : 0.0, k == 2 ? h.z : 0.0);
    gl_Position = gl_in[k].gl_Position;
    EmitVertex();
  }
  EndPrimitive();
}
