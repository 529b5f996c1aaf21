// FrameTarget and Overlays (view_draw.h): small GLSL 430 programs for lines and points, one that
// reads positions from a tessellation buffer as a vertex attribute (sub-triangle edges), and one that
// pulls positions and normals from it as a storage buffer (normal whiskers).
#include "apps/view/view_draw.h"

#include <algorithm>
#include <cstring>
#include <string>

#include <glad/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include <sffd/error.h>
#include "pipelines/patch_output.h"

namespace sffd::view {
namespace {

const char* kLineVert = R"(#version 430 core
layout(location = 0) in vec3 aPos;
layout(location = 1) in vec4 aColor;
uniform mat4 uMvp;
uniform float uPointSize;
out vec4 vColor;
void main() {
  vColor = aColor;
  gl_Position = uMvp * vec4(aPos, 1.0);
  gl_PointSize = uPointSize * (aColor.a > 0.99 ? 1.4 : 1.0);
}
)";
const char* kLineFrag = R"(#version 430 core
in vec4 vColor;
uniform int uRound;
out vec4 fragColor;
void main() {
  if (uRound != 0 && length(gl_PointCoord - vec2(0.5)) > 0.5) discard;
  fragColor = vColor;
}
)";
// Tessellation positions as a vertex attribute (16-byte stride), pulled slightly towards the eye so
// that lines on the surface win the depth test.
const char* kTessVert = R"(#version 430 core
layout(location = 0) in vec3 aPos;
uniform mat4 uMvp;
void main() {
  gl_Position = uMvp * vec4(aPos, 1.0);
  gl_Position.z -= 2e-4 * gl_Position.w;
}
)";
const char* kNormalsVert = R"(#version 430 core
layout(std430, binding = 0) readonly buffer Tess { vec4 tess[]; };
uniform mat4 uMvp;
uniform int uNv;
uniform float uLength;
void main() {
  int vert = gl_VertexID / 2;
  int patchIndex = vert / uNv;
  int local = vert - patchIndex * uNv;
  int base = 2 * uNv * patchIndex;
  vec3 p = tess[base + local].xyz;
  vec3 n = tess[base + uNv + local].xyz;
  gl_Position = uMvp * vec4(p + float(gl_VertexID & 1) * uLength * n, 1.0);
  gl_Position.z -= 2e-4 * gl_Position.w;
}
)";
const char* kFlatFrag = R"(#version 430 core
uniform vec4 uColor;
out vec4 fragColor;
void main() { fragColor = uColor; }
)";

GLuint compileProgram(const char* vs, const char* fs, const char* what) {
  GLuint p = glCreateProgram();
  for (auto [stage, src] : {std::pair<GLenum, const char*>{GL_VERTEX_SHADER, vs}, {GL_FRAGMENT_SHADER, fs}}) {
    GLuint s = glCreateShader(stage);
    glShaderSource(s, 1, &src, nullptr);
    glCompileShader(s);
    GLint ok = 0;
    glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
    if (!ok) {
      char log[1024] = {0};
      glGetShaderInfoLog(s, sizeof log, nullptr, log);
      glDeleteShader(s);
      glDeleteProgram(p);
      throw Error(ErrorKind::Internal, std::string("view: the ") + what + " shader does not compile: " + log);
    }
    glAttachShader(p, s);
    glDeleteShader(s);
  }
  glLinkProgram(p);
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    char log[1024] = {0};
    glGetProgramInfoLog(p, sizeof log, nullptr, log);
    glDeleteProgram(p);
    throw Error(ErrorKind::Internal, std::string("view: the ") + what + " program does not link: " + log);
  }
  return p;
}

glm::mat4 mvpOf(const gl::SlotCamera& cam) { return glm::mat4(cam.projection * cam.view); }
// The same for positions in a source's frame, composed in double (the translation to a far origin cancels
// against the view's there, before anything becomes float).
glm::mat4 mvpOf(const gl::SlotCamera& cam, const TessSource& s) {
  return glm::mat4(cam.projection * cam.view * glm::translate(glm::dmat4(1.0), s.origin) * glm::scale(glm::dmat4(1.0), glm::dvec3(1.0 / s.scale)));
}

}  // namespace

// ---- FrameTarget ----

FrameTarget::~FrameTarget() { release(); }

void FrameTarget::release() {
  if (msFbo_) glDeleteFramebuffers(1, &msFbo_);
  if (fbo_) glDeleteFramebuffers(1, &fbo_);
  for (unsigned rb : {msColor_, msDepth_, color_})
    if (rb) glDeleteRenderbuffers(1, &rb);
  msFbo_ = msColor_ = msDepth_ = fbo_ = color_ = 0;
  width_ = height_ = samples_ = 0;
}

void FrameTarget::bind(int width, int height, int wanted) {
  if (width != width_ || height != height_ || wanted != samples_ || !msFbo_) {
    release();
    GLint maxSamples = 1;
    glGetIntegerv(GL_MAX_SAMPLES, &maxSamples);
    // 1 asks for no multisampling at all (0 samples: a plain buffer, the resolve a copy).
    const int samples = wanted > 1 && maxSamples > 1 ? std::min(wanted, int(maxSamples)) : 0;
    glGenFramebuffers(1, &msFbo_);
    glGenRenderbuffers(1, &msColor_);
    glGenRenderbuffers(1, &msDepth_);
    glBindRenderbuffer(GL_RENDERBUFFER, msColor_);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_RGBA8, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, msDepth_);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, GL_DEPTH_COMPONENT24, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, msFbo_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, msColor_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, msDepth_);
    bool ok = glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    glGenFramebuffers(1, &fbo_);
    glGenRenderbuffers(1, &color_);
    glBindRenderbuffer(GL_RENDERBUFFER, color_);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_);
    ok = ok && glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
    if (!ok || glGetError() == GL_OUT_OF_MEMORY) {
      release();
      glBindFramebuffer(GL_FRAMEBUFFER, 0);
      throw deviceError("view: no " + std::to_string(width) + "x" + std::to_string(height) + " framebuffer");
    }
    width_ = width;
    height_ = height;
    samples_ = wanted;
  }
  glBindFramebuffer(GL_FRAMEBUFFER, msFbo_);
}

void FrameTarget::resolve(bool toWindow) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, msFbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fbo_);
  glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  if (toWindow) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glBlitFramebuffer(0, 0, width_, height_, 0, 0, width_, height_, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

gl::Image FrameTarget::read() const {
  gl::Image img;
  img.width = width_;
  img.height = height_;
  std::vector<uint8_t> raw(size_t(width_) * height_ * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, raw.data());
  glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  img.rgba.resize(raw.size());
  const size_t row = size_t(width_) * 4;
  for (int y = 0; y < height_; ++y) std::memcpy(&img.rgba[size_t(y) * row], &raw[size_t(height_ - 1 - y) * row], row);
  for (size_t i = 3; i < img.rgba.size(); i += 4) img.rgba[i] = 255;
  return img;
}

// ---- Overlays ----

std::vector<uint32_t> tessBoundaryLines(int L) {
  auto idx = [](int r, int t) { return uint32_t(r * (r + 1) / 2 + t); };
  std::vector<uint32_t> out;
  for (int r = 0; r < L; ++r) {
    out.insert(out.end(), {idx(r, 0), idx(r + 1, 0)});       // t = 0 side
    out.insert(out.end(), {idx(r, r), idx(r + 1, r + 1)});   // t = r side
    out.insert(out.end(), {idx(L, r), idx(L, r + 1)});       // r = L side
  }
  return out;
}

Overlays::Overlays() {
  lineProgram_ = compileProgram(kLineVert, kLineFrag, "lattice");
  tessProgram_ = compileProgram(kTessVert, kFlatFrag, "edges");
  GLint vertexSsbos = 0;
  glGetIntegerv(GL_MAX_VERTEX_SHADER_STORAGE_BLOCKS, &vertexSsbos);
  if (vertexSsbos > 0) normalsProgram_ = compileProgram(kNormalsVert, kFlatFrag, "normals");
  glGenVertexArrays(1, &vao_);
  glGenBuffers(1, &vbo_);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 7 * sizeof(float), nullptr);
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, 7 * sizeof(float), reinterpret_cast<void*>(3 * sizeof(float)));
  glBindVertexArray(0);
  glGenVertexArrays(1, &tessVao_);
  glGenBuffers(1, &edgeIndex_);
}

Overlays::~Overlays() {
  for (unsigned p : {lineProgram_, tessProgram_, normalsProgram_})
    if (p) glDeleteProgram(p);
  glDeleteVertexArrays(1, &vao_);
  glDeleteVertexArrays(1, &tessVao_);
  glDeleteBuffers(1, &vbo_);
  glDeleteBuffers(1, &edgeIndex_);
}

void Overlays::lines(const std::vector<float>& v, unsigned mode, const glm::mat4& mvp, float pointSize) {
  if (v.empty()) return;
  glUseProgram(lineProgram_);
  glUniformMatrix4fv(glGetUniformLocation(lineProgram_, "uMvp"), 1, GL_FALSE, glm::value_ptr(mvp));
  glUniform1f(glGetUniformLocation(lineProgram_, "uPointSize"), pointSize);
  glUniform1i(glGetUniformLocation(lineProgram_, "uRound"), mode == GL_POINTS ? 1 : 0);
  glBindVertexArray(vao_);
  glBindBuffer(GL_ARRAY_BUFFER, vbo_);
  glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(v.size() * sizeof(float)), v.data(), GL_STREAM_DRAW);
  glDrawArrays(mode, 0, GLsizei(v.size() / 7));
  glBindVertexArray(0);
}

void Overlays::drawLattice(const gl::SlotCamera& cam, const Lattice& L, const std::vector<size_t>& selection) {
  glViewport(cam.x, cam.y, cam.width, cam.height);
  glDisable(GL_DEPTH_TEST);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glEnable(GL_PROGRAM_POINT_SIZE);
  const glm::mat4 mvp = mvpOf(cam);
  std::vector<float> e, p;
  auto put = [](std::vector<float>& v, const glm::dvec3& x, glm::vec4 c) {
    v.insert(v.end(), {float(x.x), float(x.y), float(x.z), c.r, c.g, c.b, c.a});
  };
  const glm::vec4 edge(0.15f, 0.30f, 0.60f, 0.55f), point(0.95f, 0.55f, 0.10f, 0.95f), sel(0.85f, 0.05f, 0.05f, 1.0f);
  const auto& cp = L.controlPoints;
  for (int i = 0; i < L.counts[0]; ++i)
    for (int j = 0; j < L.counts[1]; ++j)
      for (int k = 0; k < L.counts[2]; ++k) {
        size_t a = L.index(i, j, k);
        if (a >= cp.size()) continue;
        if (i + 1 < L.counts[0]) put(e, cp[a], edge), put(e, cp[L.index(i + 1, j, k)], edge);
        if (j + 1 < L.counts[1]) put(e, cp[a], edge), put(e, cp[L.index(i, j + 1, k)], edge);
        if (k + 1 < L.counts[2]) put(e, cp[a], edge), put(e, cp[L.index(i, j, k + 1)], edge);
      }
  for (size_t a = 0; a < cp.size(); ++a)
    if (!std::binary_search(selection.begin(), selection.end(), a)) put(p, cp[a], point);
  for (size_t a : selection)
    if (a < cp.size()) put(p, cp[a], sel);   // drawn last: on top
  const float size = std::clamp(float(std::min(cam.width, cam.height)) / 110.0f, 5.0f, 14.0f);
  lines(e, GL_LINES, mvp, size);
  lines(p, GL_POINTS, mvp, size);
  glDisable(GL_BLEND);
}

void Overlays::drawRect(double x0, double y0, double x1, double y1, int W, int H) {
  glViewport(0, 0, W, H);
  glDisable(GL_DEPTH_TEST);
  auto nx = [&](double x) { return float(x / W * 2 - 1); };
  auto ny = [&](double y) { return float(1 - y / H * 2); };
  const glm::vec4 c(0.1f, 0.1f, 0.1f, 1.0f);
  std::vector<float> v;
  const double xs[4] = {x0, x1, x1, x0}, ys[4] = {y0, y0, y1, y1};
  for (int s = 0; s < 4; ++s)
    for (int t : {s, (s + 1) % 4}) v.insert(v.end(), {nx(xs[t]), ny(ys[t]), 0.0f, c.r, c.g, c.b, c.a});
  lines(v, GL_LINES, glm::mat4(1.0f), 1.0f);
}

void Overlays::drawTessEdges(const gl::SlotCamera& cam, const std::vector<TessSource>& sources) {
  if (sources.empty()) return;
  size_t maxPatches = 0;
  for (const TessSource& s : sources) maxPatches = std::max(maxPatches, s.patches);
  const int level = sources.front().level;
  const size_t nv = size_t(tessVertexCount(level));
  if (maxPatches > edgeIndexPatches_ || level != edgeIndexLevel_) {
    std::vector<uint32_t> local = tessBoundaryLines(level), all;
    all.reserve(local.size() * maxPatches);
    for (size_t p = 0; p < maxPatches; ++p)
      for (uint32_t i : local) all.push_back(uint32_t(2 * nv * p + i));
    glBindVertexArray(tessVao_);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, edgeIndex_);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(all.size() * 4), all.data(), GL_STATIC_DRAW);
    glBindVertexArray(0);
    edgeIndexPatches_ = maxPatches;
    edgeIndexLevel_ = level;
  }
  glViewport(cam.x, cam.y, cam.width, cam.height);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glUseProgram(tessProgram_);
  glUniform4f(glGetUniformLocation(tessProgram_, "uColor"), 0.55f, 0.10f, 0.05f, 1.0f);
  glBindVertexArray(tessVao_);
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, edgeIndex_);
  for (const TessSource& s : sources) {
    if (!s.buffer || !s.patches) continue;
    const glm::mat4 mvp = mvpOf(cam, s);
    glUniformMatrix4fv(glGetUniformLocation(tessProgram_, "uMvp"), 1, GL_FALSE, glm::value_ptr(mvp));
    glBindBuffer(GL_ARRAY_BUFFER, s.buffer);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 16, nullptr);
    glDrawElements(GL_LINES, GLsizei(s.patches * 6 * level), GL_UNSIGNED_INT, nullptr);
  }
  glBindVertexArray(0);
  glDepthFunc(GL_LESS);
}

void Overlays::drawNormals(const gl::SlotCamera& cam, const std::vector<TessSource>& sources, float length) {
  if (!normalsProgram_) return;
  glViewport(cam.x, cam.y, cam.width, cam.height);
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LEQUAL);
  glUseProgram(normalsProgram_);
  glUniform4f(glGetUniformLocation(normalsProgram_, "uColor"), 0.05f, 0.35f, 0.75f, 1.0f);
  glBindVertexArray(tessVao_);
  for (const TessSource& s : sources) {
    if (!s.buffer || !s.patches) continue;
    const glm::mat4 mvp = mvpOf(cam, s);
    glUniformMatrix4fv(glGetUniformLocation(normalsProgram_, "uMvp"), 1, GL_FALSE, glm::value_ptr(mvp));
    glUniform1f(glGetUniformLocation(normalsProgram_, "uLength"), float(length * s.scale));   // world length in the frame's units
    const int nv = tessVertexCount(s.level);
    glUniform1i(glGetUniformLocation(normalsProgram_, "uNv"), nv);
    glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, s.buffer);
    glDrawArrays(GL_LINES, 0, GLsizei(2 * s.patches * size_t(nv)));
  }
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, 0);
  glBindVertexArray(0);
  glDepthFunc(GL_LESS);
}

}  // namespace sffd::view
