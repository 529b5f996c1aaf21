#include "backends/opengl/gl_programs.h"

#include <glad/gl.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <string>

#include <sffd/error.h>
#include "backends/opengl/gl_check.h"
#include "backends/opengl/gl_es_limits.h"
#include "kernels/common/shader_layout.h"

namespace sffd::gl {

namespace {

// Lowers "#version 450" to the context's version (4.3, 4.4): the kernels use nothing past GLSL 4.30.
// The ES form ("#version 310 es", made at build time) is left as it is.
void fitVersion(std::string& src, int contextVersion) {
  if (src.rfind("#version ", 0) != 0 || src.rfind("#version 310 es", 0) == 0) return;
  int want = std::atoi(src.c_str() + 9);
  int have = contextVersion * 10;
  if (want > have && have >= 430) src.replace(9, 3, std::to_string(have));
}

// What a linked compute program uses, as GL reports it.
ProgramResources queryResources(GLuint prog) {
  ProgramResources r;
  GLint blocks = 0;
  glGetProgramInterfaceiv(prog, GL_SHADER_STORAGE_BLOCK, GL_ACTIVE_RESOURCES, &blocks);
  r.storageBlocks = blocks;
  for (GLint i = 0; i < blocks; ++i) {
    const GLenum prop = GL_BUFFER_BINDING;
    GLint binding = 0;
    glGetProgramResourceiv(prog, GL_SHADER_STORAGE_BLOCK, GLuint(i), 1, &prop, 1, nullptr, &binding);
    r.maxStorageBinding = std::max(r.maxStorageBinding, binding);
  }
  glGetProgramInterfaceiv(prog, GL_UNIFORM_BLOCK, GL_ACTIVE_RESOURCES, &blocks);
  for (GLint i = 0; i < blocks; ++i) {
    const GLenum prop = GL_BUFFER_DATA_SIZE;
    GLint size = 0;
    glGetProgramResourceiv(prog, GL_UNIFORM_BLOCK, GLuint(i), 1, &prop, 1, nullptr, &size);
    r.maxUniformBlockBytes = std::max(r.maxUniformBlockBytes, size);
  }
  glGetProgramiv(prog, GL_COMPUTE_WORK_GROUP_SIZE, r.groupSize);
  return r;
}

// The first ES 3.1 minimum limit the program is past, or "" when it fits them all.
std::string pastEsMinimum(const ProgramResources& r) {
  auto past = [](const char* what, long long have, long long limit) {
    return std::string(what) + " " + std::to_string(have) + " (OpenGL ES 3.1 guarantees " + std::to_string(limit) + ")";
  };
  if (r.storageBlocks > es31::kMaxComputeStorageBlocks)
    return past("storage blocks", r.storageBlocks, es31::kMaxComputeStorageBlocks);
  if (r.maxStorageBinding >= es31::kMaxStorageBindings)
    return past("storage binding", r.maxStorageBinding, es31::kMaxStorageBindings - 1);
  if (r.maxUniformBlockBytes > es31::kMaxUniformBlockSize)
    return past("uniform block bytes", r.maxUniformBlockBytes, es31::kMaxUniformBlockSize);
  long long invocations = 1;
  for (int i = 0; i < 3; ++i) {
    if (r.groupSize[i] > es31::kMaxGroupSize[i]) return past("work-group size", r.groupSize[i], es31::kMaxGroupSize[i]);
    invocations *= r.groupSize[i];
  }
  if (invocations > es31::kMaxInvocations) return past("work-group invocations", invocations, es31::kMaxInvocations);
  return {};
}

std::string shaderLog(GLuint object, bool isProgram) {
  GLint len = 0;
  if (isProgram)
    glGetProgramiv(object, GL_INFO_LOG_LENGTH, &len);
  else
    glGetShaderiv(object, GL_INFO_LOG_LENGTH, &len);
  std::string log(static_cast<size_t>(std::max(len, 1)), '\0');
  if (isProgram)
    glGetProgramInfoLog(object, len, nullptr, log.data());
  else
    glGetShaderInfoLog(object, len, nullptr, log.data());
  log.resize(std::strlen(log.c_str()));
  return log;
}

}  // namespace

Programs::Programs(const DeviceInfo& device, int glVersion, bool es, bool heldToEsMinimum, bool parallelCompile)
    : device_(device), glVersion_(glVersion), es_(es), heldToEsMinimum_(heldToEsMinimum), parallelCompile_(parallelCompile) {}

const Program& Programs::get(const EmbeddedKernel& kernel, KernelVariant variant) {
  variant = forDevice(variant, device_);
  const Key key(&kernel, variantKey(variant));
  auto it = programs_.find(key);
  if (it != programs_.end()) return it->second;
  start(kernel, variant);
  auto b = builds_.find(key);
  Build build = std::move(b->second);
  builds_.erase(b);
  return programs_.emplace(key, finish(kernel, variant, std::move(build))).first->second;
}

void Programs::precompile(const std::vector<KernelUse>& uses) {
  if (!parallelCompile_) return;
  for (const KernelUse& use : uses) {
    const EmbeddedKernel* kernel = findKernel(use.kernel);
    // What cannot be built fails at its dispatch, as the interface says.
    if (kernel && (!use.variant.f64 || device_.limits.float64)) start(*kernel, use.variant);
  }
}

void Programs::settle() {
  for (auto& [key, b] : builds_) {
    if (!b.compiling) continue;
    GLint done = GL_FALSE;
    glGetProgramiv(b.program, GL_COMPLETION_STATUS_KHR, &done);
    if (done) b.compiling.reset();
  }
}

void Programs::release() {
  for (auto& [key, p] : programs_) glDeleteProgram(p.name);
  for (auto& [key, b] : builds_) {
    glDeleteShader(b.shader);
    glDeleteProgram(b.program);
  }
  programs_.clear();
  builds_.clear();
}

// Issues the compile and link of a variant (forDevice's) not built or building yet.
void Programs::start(const EmbeddedKernel& kernel, KernelVariant variant) {
  variant = forDevice(variant, device_);
  const Key key(&kernel, variantKey(variant));
  if (programs_.count(key) || builds_.count(key)) return;
  if (variant.f64 && !device_.limits.float64)
    throw deviceError(device_.api + ": the device has no float64 for " + std::string(kernel.name) + " (" +
                      variantName(variant) + ")");
  Build b;
  b.compiling = std::make_unique<CompileScope>(device_.api, kernel.name, variant);
  std::string src = glslForVariant(kernel, variant, es_);
  fitVersion(src, glVersion_);
  b.shader = glCreateShader(GL_COMPUTE_SHADER);
  const char* text = src.c_str();
  glShaderSource(b.shader, 1, &text, nullptr);
  glCompileShader(b.shader);
  b.program = glCreateProgram();
  glAttachShader(b.program, b.shader);
  glLinkProgram(b.program);
  builds_.emplace(key, std::move(b));
}

// Waits for a build's compile and link (the status queries block until the driver is done).
Program Programs::finish(const EmbeddedKernel& kernel, KernelVariant variant, Build b) {
  std::string what = std::string(kernel.name) + " (" + variantName(variant) + ")";
  GLint ok = 0;
  glGetShaderiv(b.shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    std::string log = shaderLog(b.shader, false);
    glDeleteShader(b.shader);
    glDeleteProgram(b.program);
    throw Error(ErrorKind::Internal, "gl: compiling kernel " + what + " failed:\n" + log);
  }
  glGetProgramiv(b.program, GL_LINK_STATUS, &ok);
  glDetachShader(b.program, b.shader);
  glDeleteShader(b.shader);
  const GLuint prog = b.program;
  if (!ok) {
    std::string log = shaderLog(prog, true);
    glDeleteProgram(prog);
    throw Error(ErrorKind::Internal, "gl: linking kernel " + what + " failed:\n" + log);
  }
  b.compiling.reset();
  Program p;
  p.name = prog;
  p.resources = queryResources(prog);
  if (heldToEsMinimum_) {
    std::string past = pastEsMinimum(p.resources);
    if (!past.empty()) {
      glDeleteProgram(prog);
      throw deviceError("gles: kernel " + what + " uses " + past + "; SFFD_GLES_LIMITS=device uses the device's own limits");
    }
  }
  GLint blocks = 0;
  glGetProgramiv(prog, GL_ACTIVE_UNIFORM_BLOCKS, &blocks);
  for (GLint i = 0; i < blocks; ++i) {
    GLint binding = -1, size = 0;
    glGetActiveUniformBlockiv(prog, static_cast<GLuint>(i), GL_UNIFORM_BLOCK_BINDING, &binding);
    glGetActiveUniformBlockiv(prog, static_cast<GLuint>(i), GL_UNIFORM_BLOCK_DATA_SIZE, &size);
    if (binding == SFFD_BINDING_PARAMS) p.paramsBlockSize = size;
  }
  checkGl("building kernel " + what);
  return p;
}

}  // namespace sffd::gl
