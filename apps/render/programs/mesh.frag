#version 430 core
in FragData {
  vec3 viewPos; vec3 viewNormal; float scalar;
  flat vec3 seenNormal;
  noperspective vec3 edgeDist;
} fi;
out vec4 fragColor;
uniform vec3 uBaseColor;     // linear
uniform int uUseScalars;
uniform vec2 uScalarRange;   // min, 1 / (max - min)
uniform int uWireframe;
uniform float uWireWidth;    // half width in pixels

vec3 viridis(float t) {
  t = clamp(t, 0.0, 1.0);
  const vec3 c0 = vec3(0.2777273272234177, 0.005407344544966578, 0.3340998053353061);
  const vec3 c1 = vec3(0.1050930431085774, 1.404613529898575, 1.384590162594685);
  const vec3 c2 = vec3(-0.3308618287255563, 0.214847559468213, 0.09509516302823659);
  const vec3 c3 = vec3(-4.634230498983486, -5.799100973351585, -19.33244095627987);
  const vec3 c4 = vec3(6.228269936347081, 14.17993336680509, 56.69055260068105);
  const vec3 c5 = vec3(4.776384997670288, -13.74514537774601, -65.35303263337234);
  const vec3 c6 = vec3(-5.435455855934631, 4.645852612178535, 26.3124352495832);
  return clamp(c0 + t * (c1 + t * (c2 + t * (c3 + t * (c4 + t * (c5 + t * c6))))), 0.0, 1.0);
}
vec3 toLinear(vec3 c) { return pow(max(c, vec3(0.0)), vec3(2.2)); }

void main() {
  vec3 n = fi.viewNormal;
  float nl = length(n);
  n = nl > 1e-12 ? n / nl : fi.seenNormal;
  if (dot(n, fi.seenNormal) < 0.0) n = -n;   // two-sided: light the side that is seen
  vec3 v = normalize(-fi.viewPos);

  vec3 albedo = uUseScalars != 0 ? toLinear(viridis((fi.scalar - uScalarRange.x) * uScalarRange.y)) : uBaseColor;

  // Key light from the upper left, a cooler fill from the right, a rim light from behind, and a
  // hemisphere ambient (sky above, ground below, in view space).
  const vec3 keyDir = normalize(vec3(-0.55, 0.65, 0.50));
  const vec3 fillDir = normalize(vec3(0.75, -0.10, 0.40));
  const vec3 rimDir = normalize(vec3(0.20, 0.60, -0.75));
  const vec3 keyColor = vec3(1.00, 0.97, 0.92) * 1.15;
  const vec3 fillColor = vec3(0.75, 0.85, 1.00) * 0.26;
  const vec3 rimColor = vec3(1.0) * 0.35;
  vec3 ambient = mix(vec3(0.025, 0.025, 0.03), vec3(0.085, 0.09, 0.105), 0.5 + 0.5 * n.y);

  vec3 diffuse = keyColor * max(dot(n, keyDir), 0.0) + fillColor * max(dot(n, fillDir), 0.0) +
                 rimColor * max(dot(n, rimDir), 0.0);
  float specKey = pow(max(dot(n, normalize(keyDir + v)), 0.0), 40.0);
  float specFill = pow(max(dot(n, normalize(fillDir + v)), 0.0), 24.0);
  vec3 color = albedo * (ambient + diffuse) + 0.25 * keyColor * specKey + 0.04 * specFill;

  color = pow(clamp(color, 0.0, 1.0), vec3(1.0 / 2.2));
  if (uWireframe != 0) {
    float d = min(fi.edgeDist.x, min(fi.edgeDist.y, fi.edgeDist.z));
    float a = 1.0 - smoothstep(uWireWidth - 0.5, uWireWidth + 0.5, d);
    color = mix(color, vec3(0.10, 0.11, 0.13), 0.8 * a);
  }
  fragColor = vec4(color, 1.0);
}
