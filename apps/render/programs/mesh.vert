#version 430 core
// The mesh pass: view-space position and normal, and a per-vertex scalar for the heat map.
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec3 aNormal;
layout(location = 2) in float aScalar;
uniform mat4 uModelView;
uniform mat4 uProjection;
out VertexData { vec3 viewPos; vec3 viewNormal; float scalar; } vo;
void main() {
  vec4 p = uModelView * vec4(aPos, 1.0);
  vo.viewPos = p.xyz;
  vo.viewNormal = mat3(uModelView) * aNormal;   // rotation and uniform translation only: no scaling
  vo.scalar = aScalar;
  gl_Position = uProjection * p;
}
