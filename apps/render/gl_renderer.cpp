// The renderer (gl_renderer.h): GLSL 430 programs for the meshes (vertex + geometry + fragment: the
// geometry stage gives each fragment its distances to the triangle's edges for the wireframe and the
// triangle's own normal for two-sided lighting), the background and the 2-D overlay (captions, legend),
// an offscreen framebuffer resolved from 4x multisampling. The programs are apps/render/programs/*,
// the overlay font overlay.cpp, PNG files png_io.cpp.
#include "apps/render/gl_renderer.h"

#include "apps/render/overlay.h"
#include "apps/render/render_programs.h"   // generated from apps/render/programs/ at configure time

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <cerrno>
#include <cmath>
#include <csetjmp>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <ostream>

#include <glad/gl.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "backends/opengl/gl_check.h"
#include "io/atomic_file.h"
#include <sffd/error.h>

namespace sffd::gl {

namespace {

// ---------------------------------------------------------------------------------------------
// Shaders (the GLSL sources are apps/render/programs/*, embedded as kMeshVert, kMeshGeom, ...)
// ---------------------------------------------------------------------------------------------

GLuint compile(GLenum stage, const char* source, const char* what) {
  GLuint s = glCreateShader(stage);
  glShaderSource(s, 1, &source, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetShaderiv(s, GL_INFO_LOG_LENGTH, &len);
    std::string log(static_cast<size_t>(std::max(len, 1)), '\0');
    glGetShaderInfoLog(s, len, nullptr, log.data());
    glDeleteShader(s);
    throw Error(ErrorKind::Internal, std::string("render: the ") + what + " shader does not compile: " + log.c_str());
  }
  return s;
}

GLuint link(std::initializer_list<std::pair<GLenum, const char*>> stages, const char* what) {
  GLuint p = glCreateProgram();
  std::vector<GLuint> shaders;
  try {
    for (const auto& [stage, source] : stages) shaders.push_back(compile(stage, source, what));
  } catch (...) {
    for (GLuint s : shaders) glDeleteShader(s);
    glDeleteProgram(p);
    throw;
  }
  for (GLuint s : shaders) glAttachShader(p, s);
  glLinkProgram(p);
  for (GLuint s : shaders) {
    glDetachShader(p, s);
    glDeleteShader(s);
  }
  GLint ok = 0;
  glGetProgramiv(p, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetProgramiv(p, GL_INFO_LOG_LENGTH, &len);
    std::string log(static_cast<size_t>(std::max(len, 1)), '\0');
    glGetProgramInfoLog(p, len, nullptr, log.data());
    glDeleteProgram(p);
    throw Error(ErrorKind::Internal, std::string("render: the ") + what + " program does not link: " + log.c_str());
  }
  return p;
}

glm::vec3 toLinear(glm::vec3 c) {
  return {std::pow(std::max(c.r, 0.f), 2.2f), std::pow(std::max(c.g, 0.f), 2.2f), std::pow(std::max(c.b, 0.f), 2.2f)};
}

glm::dvec3 axisVector(UpAxis a) {
  switch (a) {
    case UpAxis::PosX: return {1, 0, 0};
    case UpAxis::PosY: return {0, 1, 0};
    case UpAxis::PosZ: return {0, 0, 1};
    case UpAxis::NegX: return {-1, 0, 0};
    case UpAxis::NegY: return {0, -1, 0};
    case UpAxis::NegZ: return {0, 0, -1};
  }
  return {0, 0, 1};
}
// The axis the eye lies on at azimuth 0: with right = up x front, (right, up, front) is right-handed,
// as (x, y, z) is for a GL camera. z up: front -y, right +x. y up: front +z, right +x. x up: front +z.
glm::dvec3 frontVector(UpAxis a) {
  switch (a) {
    case UpAxis::PosZ: return {0, -1, 0};
    case UpAxis::NegZ: return {0, 1, 0};
    case UpAxis::PosY: return {0, 0, 1};
    case UpAxis::NegY: return {0, 0, -1};
    case UpAxis::PosX: return {0, 0, 1};
    case UpAxis::NegX: return {0, 0, -1};
  }
  return {0, -1, 0};
}

}  // namespace

UpAxis parseUpAxis(const std::string& text) {
  std::string t = text;
  if (!t.empty() && t[0] == '+') t = t.substr(1);
  if (t == "x") return UpAxis::PosX;
  if (t == "y") return UpAxis::PosY;
  if (t == "z") return UpAxis::PosZ;
  if (t == "-x") return UpAxis::NegX;
  if (t == "-y") return UpAxis::NegY;
  if (t == "-z") return UpAxis::NegZ;
  throw Error(ErrorKind::Input, "up axis must be x, y, z, -x, -y or -z, not '" + text + "'");
}

UpAxis upAxisFor(const std::string& option, const std::string& meshPath) {
  if (option != "auto") return parseUpAxis(option);
  std::string ext = std::filesystem::path(meshPath).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return char(std::tolower(c)); });
  return ext == ".gltf" || ext == ".glb" ? UpAxis::PosY : UpAxis::PosZ;
}

std::array<std::string, 2> legendLabels(float lo, float hi) {
  // One format for both ends: each label on its own ("%.3g") put 4.11E-13 under 0.00807.
  const double big = std::max(std::fabs(double(lo)), std::fabs(double(hi)));
  char a[32], b[32];
  if (big == 0 || (big >= 1e-3 && big < 1e5)) {
    const int decimals = big == 0 ? 0 : std::max(0, 2 - int(std::floor(std::log10(big))));   // 3 digits of the larger
    std::snprintf(a, sizeof a, "%.*f", decimals, double(lo));
    std::snprintf(b, sizeof b, "%.*f", decimals, double(hi));
  } else {
    std::snprintf(a, sizeof a, "%.2e", double(lo));
    std::snprintf(b, sizeof b, "%.2e", double(hi));
  }
  return {a, b};
}

glm::vec3 viridis(float t) {
  t = std::clamp(t, 0.0f, 1.0f);
  const glm::dvec3 c0(0.2777273272234177, 0.005407344544966578, 0.3340998053353061);
  const glm::dvec3 c1(0.1050930431085774, 1.404613529898575, 1.384590162594685);
  const glm::dvec3 c2(-0.3308618287255563, 0.214847559468213, 0.09509516302823659);
  const glm::dvec3 c3(-4.634230498983486, -5.799100973351585, -19.33244095627987);
  const glm::dvec3 c4(6.228269936347081, 14.17993336680509, 56.69055260068105);
  const glm::dvec3 c5(4.776384997670288, -13.74514537774601, -65.35303263337234);
  const glm::dvec3 c6(-5.435455855934631, 4.645852612178535, 26.3124352495832);
  double s = t;
  glm::dvec3 c = c0 + s * (c1 + s * (c2 + s * (c3 + s * (c4 + s * (c5 + s * c6)))));
  return glm::clamp(glm::vec3(c), 0.0f, 1.0f);
}

// ---------------------------------------------------------------------------------------------
// Renderer
// ---------------------------------------------------------------------------------------------

struct Renderer::GpuMesh {
  GLuint vao = 0, vbo = 0, ebo = 0;
  GLsizei indexCount = 0;
  std::vector<std::pair<GLuint, GLsizei>> external;   // BufferItem: a VAO over the caller's buffers, index count
  bool hasScalars = false;
  float scalarMin = 0, scalarMax = 0;
  std::vector<glm::vec3> points;   // positions relative to the scene centre (camera fitting)
  glm::dvec3 lo{0}, hi{0};
  std::string caption;
};

struct Renderer::Programs {
  GLuint mesh = 0, background = 0, overlay = 0;
  GLint meshModelView = -1, meshProjection = -1, meshViewport = -1, meshBaseColor = -1, meshUseScalars = -1,
        meshScalarRange = -1, meshWireframe = -1, meshWireWidth = -1;
  GLint bgBottom = -1, bgTop = -1, overlaySize = -1;
};

std::unique_ptr<Renderer> Renderer::createHeadless(Provider provider) {
  if (provider == Provider::Auto) provider = providerFromEnvironment();
  if (provider != Provider::Auto) return std::make_unique<Renderer>(std::shared_ptr<Context>(createContext(provider)));
  std::string reasons;
  for (Provider p : {Provider::EGL, Provider::OSMesa}) {
    try {
      return std::make_unique<Renderer>(std::shared_ptr<Context>(createContext(p)));
    } catch (const Error& e) {
      if (e.kind() != ErrorKind::Device) throw;
      reasons += (reasons.empty() ? "" : "; ") + std::string(e.what());
    }
  }
  throw deviceError("render: no OpenGL 4.3+ context for pictures (" + reasons + ")");
}

Renderer::Renderer(std::shared_ptr<Context> context) : context_(std::move(context)) {
  context_->activate();
  GLint major = 0, minor = 0, profile = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
  const GLubyte* r = glGetString(GL_RENDERER);
  renderer_ = r ? reinterpret_cast<const char*>(r) : "unknown";
  if (major * 10 + minor < 43)
    throw deviceError(std::string("render/") + context_->name() + ": needs OpenGL 4.3, the context is " +
                      std::to_string(major) + "." + std::to_string(minor) + " (" + renderer_ + ")");
  GLint maxRb = 0, maxSamples = 0, dims[2] = {0, 0};
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &maxRb);
  glGetIntegerv(GL_MAX_VIEWPORT_DIMS, dims);
  glGetIntegerv(GL_MAX_SAMPLES, &maxSamples);
  maxSize_ = std::min({maxRb, dims[0], dims[1]});
  maxSamples_ = std::max(maxSamples, 1);

  auto progs = std::make_unique<Programs>();
  Programs& p = *progs;
  p.mesh = link({{GL_VERTEX_SHADER, kMeshVert}, {GL_GEOMETRY_SHADER, kMeshGeom}, {GL_FRAGMENT_SHADER, kMeshFrag}}, "mesh");
  p.background = link({{GL_VERTEX_SHADER, kBackgroundVert}, {GL_FRAGMENT_SHADER, kBackgroundFrag}}, "background");
  p.overlay = link({{GL_VERTEX_SHADER, kOverlayVert}, {GL_FRAGMENT_SHADER, kOverlayFrag}}, "overlay");
  p.meshModelView = glGetUniformLocation(p.mesh, "uModelView");
  p.meshProjection = glGetUniformLocation(p.mesh, "uProjection");
  p.meshViewport = glGetUniformLocation(p.mesh, "uViewport");
  p.meshBaseColor = glGetUniformLocation(p.mesh, "uBaseColor");
  p.meshUseScalars = glGetUniformLocation(p.mesh, "uUseScalars");
  p.meshScalarRange = glGetUniformLocation(p.mesh, "uScalarRange");
  p.meshWireframe = glGetUniformLocation(p.mesh, "uWireframe");
  p.meshWireWidth = glGetUniformLocation(p.mesh, "uWireWidth");
  p.bgBottom = glGetUniformLocation(p.background, "uBottom");
  p.bgTop = glGetUniformLocation(p.background, "uTop");
  p.overlaySize = glGetUniformLocation(p.overlay, "uSize");
  programs_ = std::move(progs);

  glGenVertexArrays(1, &emptyVao_);
  glGenVertexArrays(1, &overlayVao_);
  glGenBuffers(1, &overlayVbo_);
  glBindVertexArray(overlayVao_);
  glBindBuffer(GL_ARRAY_BUFFER, overlayVbo_);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 2, GL_FLOAT, GL_FALSE, sizeof(OverlayVertex), reinterpret_cast<void*>(0));
  glEnableVertexAttribArray(1);
  glVertexAttribPointer(1, 4, GL_FLOAT, GL_FALSE, sizeof(OverlayVertex), reinterpret_cast<void*>(2 * sizeof(float)));
  glBindVertexArray(0);
  checkGlErrors("render", "setting up the renderer");
}

Renderer::~Renderer() {
  try {
    context_->activate();
  } catch (...) {
    return;   // the context is gone: so are its objects
  }
  deleteMeshes();
  releaseTarget();
  glDeleteVertexArrays(1, &emptyVao_);
  glDeleteVertexArrays(1, &overlayVao_);
  glDeleteBuffers(1, &overlayVbo_);
  if (programs_) {
    glDeleteProgram(programs_->mesh);
    glDeleteProgram(programs_->background);
    glDeleteProgram(programs_->overlay);
  }
}

void Renderer::setItems(const std::vector<RenderItem>& items) {
  // Validate everything first: a bad item leaves the previous items in place.
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi(-std::numeric_limits<double>::infinity());
  for (size_t i = 0; i < items.size(); ++i) {
    const RenderItem& it = items[i];
    if (!it.mesh) throw Error(ErrorKind::Internal, "render: item " + std::to_string(i) + " has no mesh");
    const Mesh& m = *it.mesh;
    if (!it.scalars.empty() && it.scalars.size() != m.positions.size())
      throw Error(ErrorKind::Input, "render: item " + std::to_string(i) + " has " + std::to_string(it.scalars.size()) +
                                        " scalars for " + std::to_string(m.positions.size()) + " vertices");
    for (const auto& t : m.triangles)
      for (uint32_t v : t)
        if (v >= m.positions.size())
          throw Error(ErrorKind::Input, "render: item " + std::to_string(i) + " has a triangle index out of range");
    for (const auto& p : m.positions) {
      if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z))
        throw Error(ErrorKind::Input, "render: item " + std::to_string(i) + " has a vertex that is not finite");
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  }
  const glm::dvec3 centre = std::isfinite(lo.x) ? (lo + hi) * 0.5 : glm::dvec3(0);
  const double extent = std::isfinite(lo.x) ? std::max({hi.x - lo.x, hi.y - lo.y, hi.z - lo.z}) : 0.0;

  context_->activate();
  deleteMeshes();
  sceneCentre_ = centre;
  sceneScale_ = extent > 0 && std::isfinite(extent) ? std::ldexp(1.0, -std::ilogb(extent)) : 1.0;
  for (const RenderItem& it : items) {
    const Mesh& m = *it.mesh;
    auto g = std::make_unique<GpuMesh>();
    g->caption = it.caption;
    std::vector<glm::dvec3> normals = m.normals;
    if (normals.size() != m.positions.size()) {
      Mesh copy = m;
      computeVertexNormals(copy);
      normals = copy.normals;
    }
    const size_t n = m.positions.size();
    std::vector<float> data(n * 7);
    g->points.resize(n);
    g->lo = glm::dvec3(std::numeric_limits<double>::infinity());
    g->hi = -g->lo;
    g->hasScalars = !it.scalars.empty();
    g->scalarMin = std::numeric_limits<float>::infinity();
    g->scalarMax = -std::numeric_limits<float>::infinity();
    for (size_t v = 0; v < n; ++v) {
      glm::vec3 p((m.positions[v] - centre) * sceneScale_);
      glm::vec3 nv(normals[v]);
      float s = g->hasScalars ? it.scalars[v] : 0.0f;
      if (g->hasScalars && std::isfinite(s)) {
        g->scalarMin = std::min(g->scalarMin, s);
        g->scalarMax = std::max(g->scalarMax, s);
      }
      g->points[v] = p;
      g->lo = glm::min(g->lo, glm::dvec3(p));
      g->hi = glm::max(g->hi, glm::dvec3(p));
      float* d = &data[v * 7];
      d[0] = p.x, d[1] = p.y, d[2] = p.z, d[3] = nv.x, d[4] = nv.y, d[5] = nv.z, d[6] = s;
    }
    std::vector<uint32_t> indices;
    indices.reserve(m.triangles.size() * 3);
    for (const auto& t : m.triangles) indices.insert(indices.end(), t.begin(), t.end());
    g->indexCount = static_cast<GLsizei>(indices.size());

    glGenVertexArrays(1, &g->vao);
    glGenBuffers(1, &g->vbo);
    glGenBuffers(1, &g->ebo);
    glBindVertexArray(g->vao);
    glBindBuffer(GL_ARRAY_BUFFER, g->vbo);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(data.size() * sizeof(float)), data.data(), GL_STATIC_DRAW);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g->ebo);
    glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(uint32_t)), indices.data(),
                 GL_STATIC_DRAW);
    const GLsizei stride = 7 * sizeof(float);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(0));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(3 * sizeof(float)));
    glEnableVertexAttribArray(2);
    glVertexAttribPointer(2, 1, GL_FLOAT, GL_FALSE, stride, reinterpret_cast<void*>(6 * sizeof(float)));
    glBindVertexArray(0);
    meshes_.push_back(std::move(g));
    checkGlErrors("render", "uploading a mesh");
  }
}

void Renderer::deleteMeshes() {
  for (auto& m : meshes_) {
    glDeleteVertexArrays(1, &m->vao);
    glDeleteBuffers(1, &m->vbo);
    glDeleteBuffers(1, &m->ebo);
    for (auto& e : m->external) glDeleteVertexArrays(1, &e.first);
  }
  meshes_.clear();
}

void Renderer::setBufferItem(const BufferItem& item) {
  context_->activate();
  deleteMeshes();
  sceneCentre_ = item.origin;   // the buffers' positions are the scene's float coordinates as they are
  sceneScale_ = item.scale;
  auto g = std::make_unique<GpuMesh>();
  g->caption = item.caption;
  g->points = item.fitPoints;
  for (const BufferDraw& d : item.draws) {
    if (d.indexCount == 0) continue;
    GLuint vao = 0;
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glBindBuffer(GL_ARRAY_BUFFER, d.vertexBuffer);
    glEnableVertexAttribArray(0);
    glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 16, reinterpret_cast<void*>(d.positionOffset));
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 16, reinterpret_cast<void*>(d.normalOffset));
    glDisableVertexAttribArray(2);
    glVertexAttrib1f(2, 0.0f);
    glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, d.indexBuffer);
    glBindVertexArray(0);
    g->external.push_back({vao, static_cast<GLsizei>(d.indexCount)});
  }
  meshes_.push_back(std::move(g));
  checkGlErrors("render", "setting up a buffer item");
}

namespace {

struct Fit {
  glm::dvec3 target{0};
  double distance = 1, zNear = 0.01, zFar = 100;
};

// The camera looking along -front at a target chosen so that every point projects inside
// [-fill, fill] of the frustum's half extents, as close as that allows, centred on the projection.
Fit fitPoints(const std::vector<const std::vector<glm::vec3>*>& sets, glm::dvec3 right, glm::dvec3 up,
              glm::dvec3 front, double tanX, double tanY) {
  Fit f;
  glm::dvec3 lo(std::numeric_limits<double>::infinity()), hi = -lo;
  size_t count = 0;
  for (const auto* s : sets)
    for (const glm::vec3& p : *s) {
      lo = glm::min(lo, glm::dvec3(p));
      hi = glm::max(hi, glm::dvec3(p));
      ++count;
    }
  if (count == 0) return f;
  glm::dvec3 c = (lo + hi) * 0.5;
  double d = 0, zMin = 0, zMax = 0;
  for (int iteration = 0; iteration < 3; ++iteration) {
    d = 0;
    zMin = std::numeric_limits<double>::infinity();
    zMax = -zMin;
    for (const auto* s : sets)
      for (const glm::vec3& p : *s) {
        glm::dvec3 q = glm::dvec3(p) - c;
        double x = glm::dot(q, right), y = glm::dot(q, up), z = glm::dot(q, front);
        d = std::max({d, z + std::abs(x) / tanX, z + std::abs(y) / tanY});
        zMin = std::min(zMin, z);
        zMax = std::max(zMax, z);
      }
    if (iteration == 2) break;
    // Centre the projected extents: move the target by their midpoint (at the target's depth).
    double uLo = std::numeric_limits<double>::infinity(), uHi = -uLo, vLo = uLo, vHi = -uLo;
    for (const auto* s : sets)
      for (const glm::vec3& p : *s) {
        glm::dvec3 q = glm::dvec3(p) - c;
        double depth = std::max(d - glm::dot(q, front), 1e-12);
        double u = glm::dot(q, right) / depth, v = glm::dot(q, up) / depth;
        uLo = std::min(uLo, u), uHi = std::max(uHi, u), vLo = std::min(vLo, v), vHi = std::max(vHi, v);
      }
    if (!(d > 0)) break;
    c += right * ((uLo + uHi) * 0.5 * d) + up * ((vLo + vHi) * 0.5 * d);
  }
  double extent = glm::length(hi - lo);
  if (!(d > 0)) d = extent > 0 ? extent : 1.0;
  f.target = c;
  f.distance = d;
  double farthest = d - zMin, nearest = d - zMax;
  f.zFar = farthest * 1.05 + 1e-6 * d;
  f.zNear = std::max(nearest * 0.95, f.zFar * 1e-4);
  return f;
}

}  // namespace

struct Renderer::Frame {
  float scale = 1, legendW = 0, captionH = 0, sMin = 0, sMax = 1;
  std::string minLabel, maxLabel;
  glm::dvec3 camUp{0, 0, 1};
  std::vector<SlotCamera> cams;
};

// Layout (a caption band at the top when any item has a caption, a legend panel at the right when any
// item has scalars, the rest split into equal slots, left to right) and the camera of every slot.
Renderer::Frame Renderer::frame(const RenderOptions& o, int width, int height) const {
  Frame fr;
  const float W = static_cast<float>(width), H = static_cast<float>(height);

  const float scale = std::max(1.0f, std::round(std::min(W, H) / 280.0f));
  bool anyCaption = false, anyScalars = false;
  float sMin = std::numeric_limits<float>::infinity(), sMax = -sMin;
  for (const auto& m : meshes_) {
    anyCaption |= !m->caption.empty();
    if (m->hasScalars) {
      anyScalars = true;
      sMin = std::min(sMin, m->scalarMin);
      sMax = std::max(sMax, m->scalarMax);
    }
  }
  if (o.scalarRange) sMin = (*o.scalarRange)[0], sMax = (*o.scalarRange)[1];
  if (!std::isfinite(sMin) || !std::isfinite(sMax)) sMin = 0, sMax = 1;
  const auto [minLabel, maxLabel] = legendLabels(sMin, sMax);
  float legendW = 0;
  if (anyScalars && o.legend) {
    legendW = std::max({Overlay::textWidth(maxLabel, scale), Overlay::textWidth(minLabel, scale), 8 * scale}) + 10 * scale;
    if (legendW > W * 0.4f) legendW = 0;   // too small a picture for a legend
  }
  const float captionH = anyCaption ? 13 * scale : 0;
  const int areaW = std::max(1, width - static_cast<int>(legendW));
  const int areaH = std::max(1, height - static_cast<int>(captionH));
  const int n = std::max<int>(1, static_cast<int>(meshes_.size()));

  // Cameras
  const double el = glm::radians(std::clamp(o.elevationDeg, -89.5, 89.5)), az = glm::radians(o.azimuthDeg);
  const glm::dvec3 U = axisVector(o.up), F = frontVector(o.up), R = glm::cross(U, F);
  const glm::dvec3 front = std::cos(el) * (std::cos(az) * F + std::sin(az) * R) + std::sin(el) * U;
  const glm::dvec3 right = glm::normalize(glm::cross(U, front));
  const glm::dvec3 camUp = glm::cross(front, right);
  const double fovY = glm::radians(std::clamp(o.fovYDeg, 1.0, 150.0));
  const double fill = std::clamp(o.fill, 0.05, 1.0);

  // Each item is centred in its slot; with a shared camera all are seen from the largest of their
  // fitted distances, so equal sizes look equal (every item still fits: a point that fits at one
  // distance fits at any larger one).
  const double tanY = std::tan(fovY / 2);
  std::vector<SlotCamera> cams;
  std::vector<Fit> fits;
  double shared = 0;
  for (int i = 0; i < static_cast<int>(meshes_.size()); ++i) {
    SlotCamera cam;
    cam.x = areaW * i / n;
    cam.width = areaW * (i + 1) / n - cam.x;
    cam.y = 0;
    cam.height = areaH;
    cam.fovYDeg = glm::degrees(fovY);
    cam.aspect = static_cast<double>(cam.width) / cam.height;
    if (o.placement) {   // placed by the caller: nothing to fit
      Fit f;
      f.target = (o.placement->target - sceneCentre_) * sceneScale_;
      f.distance = o.placement->distance * sceneScale_;
      f.zNear = o.placement->zNear * sceneScale_;
      f.zFar = o.placement->zFar * sceneScale_;
      fits.push_back(f);
    } else {
      fits.push_back(fitPoints({&meshes_[static_cast<size_t>(i)]->points}, right, camUp, front,
                               tanY * cam.aspect * fill, tanY * fill));
    }
    shared = std::max(shared, fits.back().distance);
    cams.push_back(cam);
  }
  for (size_t i = 0; i < cams.size(); ++i) {
    SlotCamera& cam = cams[i];
    Fit f = fits[i];
    if (o.shareCamera) {
      const double extra = shared - f.distance;
      f.distance = shared;
      f.zNear += extra;
      f.zFar += extra;
    }
    // The fits are in the scene's float coordinates; the cameras in world units.
    cam.target = f.target / sceneScale_ + sceneCentre_;
    cam.eye = cam.target + front * (f.distance / sceneScale_);
    cam.up = camUp;
    cam.zNear = f.zNear / sceneScale_;
    cam.zFar = f.zFar / sceneScale_;
    cam.view = glm::lookAt(cam.eye, cam.target, camUp);
    cam.projection = glm::perspective(fovY, cam.aspect, cam.zNear, cam.zFar);
  }

  fr.scale = scale;
  fr.legendW = legendW;
  fr.captionH = captionH;
  fr.sMin = sMin;
  fr.sMax = sMax;
  fr.minLabel = minLabel;
  fr.maxLabel = maxLabel;
  fr.camUp = camUp;
  fr.cams = std::move(cams);
  return fr;
}

std::vector<SlotCamera> Renderer::cameras(const RenderOptions& o, int width, int height) {
  return frame(o, width, height).cams;
}

std::vector<SlotCamera> Renderer::draw(const RenderOptions& o, int width, int height) {
  context_->activate();
  const Programs& P = *programs_;
  const float W = static_cast<float>(width), H = static_cast<float>(height);
  Frame fr = frame(o, width, height);
  const float scale = fr.scale, legendW = fr.legendW, captionH = fr.captionH, sMin = fr.sMin, sMax = fr.sMax;
  const std::string& minLabel = fr.minLabel;
  const std::string& maxLabel = fr.maxLabel;
  const glm::dvec3 camUp = fr.camUp;
  std::vector<SlotCamera>& cams = fr.cams;

  glDisable(GL_BLEND);
  glDisable(GL_CULL_FACE);
  glDisable(GL_SCISSOR_TEST);
  glViewport(0, 0, width, height);
  glClearColor(1, 1, 1, 1);
  glClearDepth(1.0);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);

  // Background
  glDisable(GL_DEPTH_TEST);
  glUseProgram(P.background);
  glm::vec3 top = o.gradientBackground ? glm::vec3(0.97f, 0.97f, 0.98f) : glm::vec3(0.93f, 0.93f, 0.94f);
  glm::vec3 bottom = o.gradientBackground ? glm::vec3(0.79f, 0.80f, 0.82f) : top;
  glUniform3fv(P.bgTop, 1, glm::value_ptr(top));
  glUniform3fv(P.bgBottom, 1, glm::value_ptr(bottom));
  glBindVertexArray(emptyVao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);

  // Meshes
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_LESS);
  glUseProgram(P.mesh);
  const glm::vec3 base = toLinear(o.baseColor);
  glUniform3fv(P.meshBaseColor, 1, glm::value_ptr(base));
  const float range = sMax > sMin ? 1.0f / (sMax - sMin) : 0.0f;
  glUniform2f(P.meshScalarRange, sMax > sMin ? sMin : sMin - 0.5f, sMax > sMin ? range : 1.0f);
  glUniform1i(P.meshWireframe, o.wireframe ? 1 : 0);
  glUniform1f(P.meshWireWidth, std::max(0.5f, std::min(W, H) / 1000.0f));
  for (size_t i = 0; i < meshes_.size(); ++i) {
    const GpuMesh& m = *meshes_[i];
    const SlotCamera& cam = cams[i];
    glViewport(cam.x, cam.y, cam.width, cam.height);
    // Positions on the GPU are relative to the scene centre and scaled: so are the matrices.
    glm::mat4 modelView(glm::lookAt((cam.eye - sceneCentre_) * sceneScale_, (cam.target - sceneCentre_) * sceneScale_, camUp));
    glm::mat4 projection(glm::perspective(glm::radians(cam.fovYDeg), cam.aspect, cam.zNear * sceneScale_, cam.zFar * sceneScale_));
    glUniformMatrix4fv(P.meshModelView, 1, GL_FALSE, glm::value_ptr(modelView));
    glUniformMatrix4fv(P.meshProjection, 1, GL_FALSE, glm::value_ptr(projection));
    glUniform2f(P.meshViewport, static_cast<float>(cam.width), static_cast<float>(cam.height));
    glUniform1i(P.meshUseScalars, m.hasScalars ? 1 : 0);
    glBindVertexArray(m.vao);
    if (m.indexCount > 0) glDrawElements(GL_TRIANGLES, m.indexCount, GL_UNSIGNED_INT, nullptr);
    for (const auto& [vao, count] : m.external) {
      glBindVertexArray(vao);
      glDrawElements(GL_TRIANGLES, count, GL_UNSIGNED_INT, nullptr);
    }
  }

  // Overlay: captions and legend, in pixels from the top left.
  Overlay ov;
  const glm::vec4 ink(0.16f, 0.17f, 0.20f, 1.0f);
  for (size_t i = 0; i < meshes_.size(); ++i) {
    const std::string& c = meshes_[i]->caption;
    if (c.empty()) continue;
    const SlotCamera& cam = cams[i];
    float tw = Overlay::textWidth(c, scale);
    ov.text(c, std::round(cam.x + (cam.width - tw) / 2), 4 * scale, scale, ink);
  }
  if (legendW > 0) {
    const float barW = 8 * scale, x0 = W - legendW / 2 - barW / 2, y0 = captionH + 14 * scale,
                y1 = H - 14 * scale;
    if (y1 - y0 > 16 * scale) {
      const int strips = 64;
      for (int k = 0; k < strips; ++k) {
        float ta = 1.0f - static_cast<float>(k) / strips, tb = 1.0f - static_cast<float>(k + 1) / strips;
        float ya = y0 + (y1 - y0) * k / strips, yb = y0 + (y1 - y0) * (k + 1) / strips;
        ov.quad(x0, ya, x0 + barW, yb, glm::vec4(viridis(ta), 1.0f), glm::vec4(viridis(tb), 1.0f));
      }
      const float t = std::max(1.0f, scale / 2);
      ov.quad(x0 - t, y0 - t, x0 + barW + t, y0, ink);
      ov.quad(x0 - t, y1, x0 + barW + t, y1 + t, ink);
      ov.quad(x0 - t, y0, x0, y1, ink);
      ov.quad(x0 + barW, y0, x0 + barW + t, y1, ink);
      const float cx = W - legendW / 2;
      ov.text(maxLabel, std::round(cx - Overlay::textWidth(maxLabel, scale) / 2), y0 - 10 * scale, scale, ink);
      ov.text(minLabel, std::round(cx - Overlay::textWidth(minLabel, scale) / 2), y1 + 3 * scale, scale, ink);
    }
  }
  if (!ov.v.empty()) {
    glViewport(0, 0, width, height);
    glDisable(GL_DEPTH_TEST);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glUseProgram(P.overlay);
    glUniform2f(P.overlaySize, W, H);
    glBindVertexArray(overlayVao_);
    glBindBuffer(GL_ARRAY_BUFFER, overlayVbo_);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(ov.v.size() * sizeof(OverlayVertex)), ov.v.data(),
                 GL_STREAM_DRAW);
    glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(ov.v.size()));
    glDisable(GL_BLEND);
  }
  glBindVertexArray(0);
  glUseProgram(0);
  checkGlErrors("render", "drawing");
  return cams;
}

int Renderer::drawText(const std::vector<std::string>& lines, int x, int y, int width, int height, glm::vec4 color,
                       int scale) {
  if (width < 1 || height < 1 || lines.empty()) return scale;
  context_->activate();
  const float W = static_cast<float>(width), H = static_cast<float>(height);
  if (scale <= 0) scale = static_cast<int>(std::max(1.0f, std::round(std::min(W, H) / 450.0f)));
  const float s = static_cast<float>(scale), lineH = 10 * s, pad = 3 * s;
  float textW = 0;
  for (const std::string& l : lines) textW = std::max(textW, Overlay::textWidth(l, s));
  Overlay ov;
  ov.quad(float(x), float(y), float(x) + textW + 2 * pad, float(y) + lines.size() * lineH + 2 * pad - 3 * s,
          glm::vec4(1.0f, 1.0f, 1.0f, 0.65f));
  for (size_t i = 0; i < lines.size(); ++i) ov.text(lines[i], float(x) + pad, float(y) + pad + i * lineH, s, color);
  glViewport(0, 0, width, height);
  glDisable(GL_DEPTH_TEST);
  glEnable(GL_BLEND);
  glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  glUseProgram(programs_->overlay);
  glUniform2f(programs_->overlaySize, W, H);
  glBindVertexArray(overlayVao_);
  glBindBuffer(GL_ARRAY_BUFFER, overlayVbo_);
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(ov.v.size() * sizeof(OverlayVertex)), ov.v.data(), GL_STREAM_DRAW);
  glDrawArrays(GL_TRIANGLES, 0, static_cast<GLsizei>(ov.v.size()));
  glDisable(GL_BLEND);
  glBindVertexArray(0);
  glUseProgram(0);
  checkGlErrors("render", "drawing text");
  return scale;
}

void Renderer::releaseTarget() {
  if (msFbo_) glDeleteFramebuffers(1, &msFbo_);
  if (resolveFbo_) glDeleteFramebuffers(1, &resolveFbo_);
  GLuint rbs[] = {msColor_, msDepth_, resolveColor_};
  for (GLuint rb : rbs)
    if (rb) glDeleteRenderbuffers(1, &rb);
  msFbo_ = msColor_ = msDepth_ = resolveFbo_ = resolveColor_ = 0;
  targetWidth_ = targetHeight_ = targetSamples_ = 0;
}

void Renderer::ensureTarget(int width, int height, int samples) {
  samples = std::clamp(samples, 1, maxSamples_);
  if (width == targetWidth_ && height == targetHeight_ && samples == targetSamples_ && msFbo_) return;
  releaseTarget();
  // Multisampled colour and depth where asked (falling back to one sample when the driver refuses),
  // resolved by a blit into a single-sample colour buffer that glReadPixels reads.
  for (int s : {samples, 1}) {
    glGenFramebuffers(1, &msFbo_);
    glGenRenderbuffers(1, &msColor_);
    glGenRenderbuffers(1, &msDepth_);
    glBindRenderbuffer(GL_RENDERBUFFER, msColor_);
    if (s > 1) glRenderbufferStorageMultisample(GL_RENDERBUFFER, s, GL_RGBA8, width, height);
    else glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, msDepth_);
    if (s > 1) glRenderbufferStorageMultisample(GL_RENDERBUFFER, s, GL_DEPTH_COMPONENT24, width, height);
    else glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, msFbo_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, msColor_);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, msDepth_);
    GLenum status = glCheckFramebufferStatus(GL_FRAMEBUFFER);
    GLenum err = glGetError();
    if (status == GL_FRAMEBUFFER_COMPLETE && err == GL_NO_ERROR) {
      targetSamples_ = s;
      break;
    }
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glDeleteFramebuffers(1, &msFbo_);
    glDeleteRenderbuffers(1, &msColor_);
    glDeleteRenderbuffers(1, &msDepth_);
    msFbo_ = msColor_ = msDepth_ = 0;
    if (err == GL_OUT_OF_MEMORY)
      throw deviceError("render: out of GPU memory for a " + std::to_string(width) + "x" + std::to_string(height) + " picture");
    if (s == 1) throw deviceError("render: the driver gives no " + std::to_string(width) + "x" + std::to_string(height) +
                                  " framebuffer with colour and depth");
  }
  glGenFramebuffers(1, &resolveFbo_);
  glGenRenderbuffers(1, &resolveColor_);
  glBindRenderbuffer(GL_RENDERBUFFER, resolveColor_);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, resolveFbo_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, resolveColor_);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    releaseTarget();
    throw deviceError("render: the driver gives no " + std::to_string(width) + "x" + std::to_string(height) +
                      " colour buffer to read back");
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  targetWidth_ = width;
  targetHeight_ = height;
  checkGlErrors("render", "creating the offscreen framebuffer");
}

Image Renderer::render(const RenderOptions& o) {
  if (o.width < 1 || o.height < 1 || o.width > maxSize_ || o.height > maxSize_)
    throw Error(ErrorKind::Input, "picture size " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                                      " is outside 1.." + std::to_string(maxSize_) + " on " + renderer_);
  context_->activate();
  // Fewer samples for very large pictures: 4x at 8192 x 8192 would need 2 GiB of colour and depth.
  int samples = o.samples;
  while (samples > 1 && static_cast<double>(o.width) * o.height * samples > 64e6) samples /= 2;
  ensureTarget(o.width, o.height, samples);
  glBindFramebuffer(GL_FRAMEBUFFER, msFbo_);
  Image img;
  img.cameras = draw(o, o.width, o.height);
  img.width = o.width;
  img.height = o.height;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, msFbo_);
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, resolveFbo_);
  glBlitFramebuffer(0, 0, o.width, o.height, 0, 0, o.width, o.height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, resolveFbo_);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  std::vector<uint8_t> raw(static_cast<size_t>(o.width) * o.height * 4);
  glReadPixels(0, 0, o.width, o.height, GL_RGBA, GL_UNSIGNED_BYTE, raw.data());
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  checkGlErrors("render", "reading the picture back");
  // GL rows start at the bottom; images at the top.
  img.rgba.resize(raw.size());
  const size_t row = static_cast<size_t>(o.width) * 4;
  for (int y = 0; y < o.height; ++y)
    std::memcpy(&img.rgba[static_cast<size_t>(y) * row], &raw[static_cast<size_t>(o.height - 1 - y) * row], row);
  for (size_t i = 3; i < img.rgba.size(); i += 4) img.rgba[i] = 255;
  return img;
}

}  // namespace sffd::gl
