// gl_embed: an application with its own OpenGL context (a hidden GLFW window) and its own bindings
// lets sffd work on that context, deforms a torus in strict mode, reads the result from sffd's GL
// buffer, checks the bits against the CPU device, and checks that every binding it had set is as it
// was. Exit 0: identical and untouched.
#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <GL/glcorearb.h>

#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <sffd/opengl.h>
#include <sffd/sffd.h>

#include "../common/torus.h"

// The few GL entry points the application uses, loaded through GLFW (no GL loader library needed).
#define GL_FUNCTIONS(X)                                                                                        \
  X(PFNGLCREATESHADERPROC, glCreateShader) X(PFNGLSHADERSOURCEPROC, glShaderSource)                            \
  X(PFNGLCOMPILESHADERPROC, glCompileShader) X(PFNGLCREATEPROGRAMPROC, glCreateProgram)                        \
  X(PFNGLATTACHSHADERPROC, glAttachShader) X(PFNGLLINKPROGRAMPROC, glLinkProgram)                              \
  X(PFNGLUSEPROGRAMPROC, glUseProgram) X(PFNGLGENVERTEXARRAYSPROC, glGenVertexArrays)                          \
  X(PFNGLBINDVERTEXARRAYPROC, glBindVertexArray) X(PFNGLGENBUFFERSPROC, glGenBuffers)                          \
  X(PFNGLBINDBUFFERPROC, glBindBuffer) X(PFNGLBUFFERDATAPROC, glBufferData)                                    \
  X(PFNGLBINDBUFFERBASEPROC, glBindBufferBase) X(PFNGLBINDBUFFERRANGEPROC, glBindBufferRange)                  \
  X(PFNGLGETBUFFERSUBDATAPROC, glGetBufferSubData) X(PFNGLGETINTEGER64VPROC, glGetInteger64v)                  \
  X(PFNGLGETINTEGER64I_VPROC, glGetInteger64i_v) X(PFNGLGETERRORPROC, glGetError)
#define DECLARE(type, name) static type name;
GL_FUNCTIONS(DECLARE)

static void loadGl() {
#define LOAD(type, name)                                                  \
  name = reinterpret_cast<type>(glfwGetProcAddress(#name));               \
  if (!name) throw std::runtime_error("no " #name);
  GL_FUNCTIONS(LOAD)
}

// Every binding sffd's GL work could disturb, as the application sees it.
static std::vector<GLint64> bindings() {
  std::vector<GLint64> v;
  for (GLenum e : {GL_CURRENT_PROGRAM, GL_VERTEX_ARRAY_BINDING, GL_ARRAY_BUFFER_BINDING, GL_SHADER_STORAGE_BUFFER_BINDING,
                   GL_UNIFORM_BUFFER_BINDING, GL_COPY_READ_BUFFER_BINDING, GL_COPY_WRITE_BUFFER_BINDING,
                   GL_PIXEL_PACK_BUFFER_BINDING, GL_PIXEL_UNPACK_BUFFER_BINDING})
    glGetInteger64v(e, &v.emplace_back());
  for (GLuint i = 0; i < 8; ++i)
    for (GLenum e : {GL_SHADER_STORAGE_BUFFER_BINDING, GL_SHADER_STORAGE_BUFFER_START, GL_SHADER_STORAGE_BUFFER_SIZE,
                     GL_UNIFORM_BUFFER_BINDING, GL_UNIFORM_BUFFER_START, GL_UNIFORM_BUFFER_SIZE})
      glGetInteger64i_v(e, i, &v.emplace_back());
  return v;
}

int main() try {
  // The application's context: GL 4.3 core in a hidden window, current on this thread.
  if (!glfwInit()) throw std::runtime_error("glfwInit failed (no display?)");
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
  GLFWwindow* window = glfwCreateWindow(64, 64, "gl_embed", nullptr, nullptr);
  if (!window) throw std::runtime_error("no OpenGL 4.3 core window");
  glfwMakeContextCurrent(window);
  loadGl();

  // The application's own state: a program in use, a VAO, buffers bound where sffd binds its own.
  const char* src = "#version 430\nlayout(local_size_x = 1) in;\nvoid main() {}\n";
  GLuint shader = glCreateShader(GL_COMPUTE_SHADER), program = glCreateProgram();
  glShaderSource(shader, 1, &src, nullptr);
  glCompileShader(shader);
  glAttachShader(program, shader);
  glLinkProgram(program);
  glUseProgram(program);
  GLuint vao, buf[3];
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glGenBuffers(3, buf);
  for (GLuint b : buf) {
    glBindBuffer(GL_ARRAY_BUFFER, b);
    glBufferData(GL_ARRAY_BUFFER, 4096, nullptr, GL_STATIC_DRAW);
  }
  glBindBufferRange(GL_UNIFORM_BUFFER, 0, buf[0], 256, 1024);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, buf[1]);
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 3, buf[2], 0, 512);
  glBindBuffer(GL_COPY_READ_BUFFER, buf[2]);
  glBindBuffer(GL_COPY_WRITE_BUFFER, buf[1]);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, buf[0]);
  glBindBuffer(GL_ARRAY_BUFFER, buf[1]);
  const std::vector<GLint64> before = bindings();

  sffd::Mesh mesh = example::torus();
  sffd::Lattice lattice = sffd::fitLattice(mesh);
  sffd::applyLatticePreset(lattice, "bend", 0.5);
  size_t bad = 0;
  {
    sffd::Device gl = sffd::opengl::adoptCurrentContext(glfwGetProcAddress);
    sffd::Device cpu = sffd::Device::open({.name = "cpu"});
    std::printf("gl_embed: %s (%s) against %s\n", gl.label().c_str(), gl.info().name.c_str(), cpu.label().c_str());
    const sffd::DeformOptions classic{.method = sffd::Method::Classic, .strict = true, .precision = sffd::Precision::Float};
    sffd::Deformer onGl(gl, mesh, lattice, classic), onCpu(cpu, mesh, lattice, classic);
    onGl.deform(lattice);
    onCpu.deform(lattice);
    sffd::Mesh expected = onCpu.result();
    for (const sffd::OutputChunk& chunk : onGl.deviceOutput()) {
      // sffd's buffer, read by the application in its own context (restoring its own binding after).
      std::vector<unsigned char> bytes(chunk.bytes);
      glBindBuffer(GL_COPY_READ_BUFFER, sffd::opengl::bufferOf(onGl, chunk));
      glGetBufferSubData(GL_COPY_READ_BUFFER, GLintptr(chunk.offset), GLsizeiptr(chunk.bytes), bytes.data());
      glBindBuffer(GL_COPY_READ_BUFFER, buf[2]);
      bad += example::compareClassicChunk(chunk, bytes, expected);
    }
    std::printf("gl_embed: %zu vertices read from sffd's GL buffers; %zu differences\n", mesh.positions.size(), bad);
  }   // sffd's buffers and programs are deleted here, on the context that is still current
  const bool untouched = bindings() == before && glfwGetCurrentContext() == window && glGetError() == GL_NO_ERROR;
  if (!untouched) std::printf("gl_embed: the application's GL state changed\n");
  glfwDestroyWindow(window);
  glfwTerminate();
  return bad == 0 && untouched ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "gl_embed: %s\n", e.what());
  return 2;
}
