// Interop at the device level: a backend on an application's own Vulkan device and on its current
// GL context runs the strict smooth session to the CPU reference's bits, leaves the borrowed objects
// alive, never switches GL contexts and restores every GL binding the application had set.
#include <gtest/gtest.h>

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#include <glad/gl.h>

#include <dlfcn.h>

#include <cstdio>
#include <cstring>
#include <vector>

#include <sffd/deformer.h>
#include <sffd/error.h>
#include <sffd/opengl.h>
#include "backends/opengl/gl_backend.h"
#include "backends/opengl/gl_context.h"
#include "backends/vulkan/vk_interop.h"
#include "backends/backend_test_support.h"
#include "backends/cpu/cpu_backend.h"
#include "pipelines/deform_session.h"

using namespace sffd;

namespace {

struct Job {
  Mesh mesh;
  Lattice lattice;
  DeformSessionOptions options;
  SmoothOutput expected;   // the CPU backend's, strict float
};

Job strictJob() {
  Job j;
  j.mesh = readMesh(std::string(SFFD_TEST_DATA) + "/cube2.obj");
  glm::dvec3 lo(1e300), hi(-1e300);
  for (const glm::dvec3& p : j.mesh.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  j.lattice = makeIdentityLattice(lo - 0.01, hi + 0.01, {4, 4, 4}, {2, 2, 2});
  for (size_t i = 0; i < j.lattice.controlPoints.size(); ++i) j.lattice.controlPoints[i].x += 0.01 * double(i % 7);
  j.options.variant = {true, false};
  j.options.edgeLength = 0.5;
  j.options.level = 3;
  // The CPU backend runs the same session: the strict reference.
  std::unique_ptr<Backend> cpu = cpu::createBackend();
  DeformSession reference(*cpu, j.mesh, j.lattice, j.options);
  reference.deform(j.lattice);
  j.expected = reference.output();
  return j;
}

void expectStrictSession(Backend& backend, const Job& j) {
  DeformSession s(backend, j.mesh, j.lattice, j.options);
  s.deform(j.lattice);
  SmoothOutput out = s.output();
  EXPECT_EQ(out.tess, j.expected.tess);
  EXPECT_EQ(out.patches, j.expected.patches);
}

// ---- Vulkan: the test is the application; it creates and destroys its instance and device ----

// Validation messages about the application's instance (layer on, as an application debugging would).
size_t gAppValidationMessages = 0;
VKAPI_ATTR VkBool32 VKAPI_CALL countMessage(VkDebugUtilsMessageSeverityFlagBitsEXT, VkDebugUtilsMessageTypeFlagsEXT,
                                            const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
  ++gAppValidationMessages;
  std::fprintf(stderr, "validation: %s\n", data->pMessage);
  return VK_FALSE;
}

struct AppVulkan {
  vk::Api api = vk::Api::load();
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  uint32_t family = 0;
  bool f64 = false;

  AppVulkan() {
    auto app = vk::vkStruct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
    app.apiVersion = VK_API_VERSION_1_2;
    auto ci = vk::vkStruct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
    ci.pApplicationInfo = &app;
    const char* layer = "VK_LAYER_KHRONOS_validation";
    const char* extension = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    ci.enabledLayerCount = ci.enabledExtensionCount = 1;
    ci.ppEnabledLayerNames = &layer;
    ci.ppEnabledExtensionNames = &extension;
    bool validation = api.vkCreateInstance(&ci, nullptr, &instance) == VK_SUCCESS;
    if (!validation) {   // no layer installed: the test runs without it
      ci.enabledLayerCount = ci.enabledExtensionCount = 0;
      vk::check(api.vkCreateInstance(&ci, nullptr, &instance), "vkCreateInstance");
    }
    api.loadInstance(instance, validation);
    if (validation) {
      auto mi = vk::vkStruct<VkDebugUtilsMessengerCreateInfoEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT);
      mi.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
      mi.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
      mi.pfnUserCallback = countMessage;
      vk::check(api.vkCreateDebugUtilsMessengerEXT(instance, &mi, nullptr, &messenger), "messenger");
    }
    uint32_t n = 1;
    VkResult r = api.vkEnumeratePhysicalDevices(instance, &n, &physical);
    if (r < 0 || n == 0) throw deviceError("no Vulkan device");
    uint32_t families = 0;
    api.vkGetPhysicalDeviceQueueFamilyProperties(physical, &families, nullptr);
    std::vector<VkQueueFamilyProperties> props(families);
    api.vkGetPhysicalDeviceQueueFamilyProperties(physical, &families, props.data());
    while (family < families && !(props[family].queueFlags & VK_QUEUE_COMPUTE_BIT)) ++family;
    VkPhysicalDeviceFeatures have;
    api.vkGetPhysicalDeviceFeatures(physical, &have);
    f64 = have.shaderFloat64;
    VkPhysicalDeviceFeatures enabled{};
    enabled.shaderFloat64 = have.shaderFloat64;
    float priority = 1;
    auto qi = vk::vkStruct<VkDeviceQueueCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO);
    qi.queueFamilyIndex = family;
    qi.queueCount = 1;
    qi.pQueuePriorities = &priority;
    auto di = vk::vkStruct<VkDeviceCreateInfo>(VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO);
    di.queueCreateInfoCount = 1;
    di.pQueueCreateInfos = &qi;
    di.pEnabledFeatures = &enabled;
    vk::check(api.vkCreateDevice(physical, &di, nullptr, &device), "vkCreateDevice");
    api.loadDevice(device);
    api.vkGetDeviceQueue(device, family, 0, &queue);
  }
  ~AppVulkan() {
    api.vkDestroyDevice(device, nullptr);
    if (messenger) api.vkDestroyDebugUtilsMessengerEXT(instance, messenger, nullptr);
    api.vkDestroyInstance(instance, nullptr);
  }
  vulkan::DeviceConfig config(bool float64) const {
    return {instance, physical, device, family, queue, api.vkGetInstanceProcAddr, float64};
  }
};

TEST(VulkanInterop, AdoptedDeviceRunsStrictSessionAndStaysTheApplications) {
  SFFD_SKIP_WITHOUT("vulkan");
  Job j = strictJob();
  {
    AppVulkan app;
    for (bool viaLoader : {false, true}) {
      vulkan::DeviceConfig c = app.config(false);
      if (viaLoader) c.getInstanceProcAddr = nullptr;   // sffd opens the system loader itself
      std::unique_ptr<Backend> b = vk::adoptBackend(c);
      EXPECT_EQ(b->info().provider, "adopted");
      EXPECT_FALSE(b->info().limits.float64);   // not enabled by the config, whatever the device has
      expectStrictSession(*b, j);
      BufferId id = b->createBuffer(64);
      EXPECT_NE(vk::vkBufferOf(*b, id), VK_NULL_HANDLE);
      EXPECT_EQ(vk::vkBufferOf(*b, id + 100), VK_NULL_HANDLE);
    }
    // The device and its queue are still the application's, and usable.
    EXPECT_EQ(app.api.vkQueueWaitIdle(app.queue), VK_SUCCESS);
    EXPECT_EQ(app.api.vkDeviceWaitIdle(app.device), VK_SUCCESS);
    if (app.f64) {
      EXPECT_TRUE(vk::adoptBackend(app.config(true))->info().limits.float64);
    }
  }
  // None, the application's vkDestroyDevice included (it reports objects sffd left behind).
  EXPECT_EQ(gAppValidationMessages, 0u);
}

TEST(VulkanInterop, QueueFamilyWithoutComputeIsRefused) {
  SFFD_SKIP_WITHOUT("vulkan");
  AppVulkan app;
  vulkan::DeviceConfig c = app.config(false);
  c.queueFamily = 99;
  try {
    vk::adoptBackend(c);
    FAIL() << "expected a device error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::Device);
    EXPECT_NE(std::string(e.what()).find("queue family 99"), std::string::npos) << e.what();
  }
}

// bufferOf on sffd's own Vulkan device too, refused where the output is not a Vulkan (or GL) buffer.
TEST(VulkanInterop, BufferOfNamesTheDeformersBuffersAndRefusesOtherDevices) {
  SFFD_SKIP_WITHOUT("vulkan");
  Job j = strictJob();
  DeformOptions classic;
  classic.method = Method::Classic;
  classic.strict = true;
  classic.precision = Precision::Float;
  DeviceRequest vkRequest, cpuRequest;
  vkRequest.name = "vulkan";
  cpuRequest.name = "cpu";
  Device gpu = Device::open(vkRequest);
  Deformer d(gpu, j.mesh, j.lattice, classic);
  d.deform(j.lattice);
  ASSERT_FALSE(d.deviceOutput().empty());
  for (const OutputChunk& c : d.deviceOutput()) {
    vulkan::BufferRange r = vulkan::bufferOf(d, c);
    EXPECT_NE(r.buffer, VK_NULL_HANDLE);
    EXPECT_EQ(r.size, c.bytes);
  }
  // Each refusal says which mistake it is (a forged chunk was "the Deformer runs on vulkan, not on a Vulkan
  // device").
  auto messageOf = [](auto&& f) {
    try {
      f();
    } catch (const Error& e) {
      EXPECT_EQ(e.kind(), ErrorKind::Input) << e.what();
      return std::string(e.what());
    }
    ADD_FAILURE() << "nothing was thrown";
    return std::string();
  };
  EXPECT_NE(messageOf([&] { opengl::bufferOf(d, d.deviceOutput()[0]); }).find("not on a GL device"), std::string::npos);
  OutputChunk forged = d.deviceOutput()[0];
  forged.buffer += 1000;
  const std::string message = messageOf([&] { vulkan::bufferOf(d, forged); });
  EXPECT_NE(message.find("is not one of the Deformer's deviceOutput()"), std::string::npos) << message;
  EXPECT_EQ(message.find("not on a Vulkan device"), std::string::npos) << message;
  Device cpu = Device::open(cpuRequest);
  Deformer onCpu(cpu, j.mesh, j.lattice, classic);
  EXPECT_NE(messageOf([&] { vulkan::bufferOf(onCpu, OutputChunk{}); }).find("not on a Vulkan device"), std::string::npos);
}

// ---- GL: the application's GLFW window, with bindings of its own ----

// Every binding the GL backend may touch, as the application sees it.
std::vector<GLint64> glBindings() {
  std::vector<GLint64> v;
  auto get = [&](GLenum e) {
    GLint64 x = 0;
    glGetInteger64v(e, &x);
    v.push_back(x);
  };
  auto geti = [&](GLenum e, GLuint i) {
    GLint64 x = 0;
    glGetInteger64i_v(e, i, &x);
    v.push_back(x);
  };
  for (GLenum e : {GL_CURRENT_PROGRAM, GL_VERTEX_ARRAY_BINDING, GL_SHADER_STORAGE_BUFFER_BINDING,
                   GL_UNIFORM_BUFFER_BINDING, GL_COPY_READ_BUFFER_BINDING, GL_COPY_WRITE_BUFFER_BINDING,
                   GL_PIXEL_PACK_BUFFER_BINDING, GL_PIXEL_UNPACK_BUFFER_BINDING, GL_DISPATCH_INDIRECT_BUFFER_BINDING,
                   GL_ARRAY_BUFFER_BINDING})
    get(e);
  for (GLuint i = 0; i < 16; ++i)
    for (GLenum e : {GL_SHADER_STORAGE_BUFFER_BINDING, GL_SHADER_STORAGE_BUFFER_START, GL_SHADER_STORAGE_BUFFER_SIZE,
                     GL_UNIFORM_BUFFER_BINDING, GL_UNIFORM_BUFFER_START, GL_UNIFORM_BUFFER_SIZE})
      geti(e, i);
  return v;
}

TEST(GlInterop, AdoptedContextRunsStrictSessionRestoringTheApplicationsBindings) {
  if (!glfwInit()) GTEST_SKIP() << "no display for a GLFW window";
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 4);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_VISIBLE, GLFW_FALSE);
  GLFWwindow* window = glfwCreateWindow(32, 32, "interop", nullptr, nullptr);
  ASSERT_NE(window, nullptr);
  glfwMakeContextCurrent(window);
  ASSERT_NE(gladLoadGL(glfwGetProcAddress), 0);

  // The application's state: a program, a VAO, buffers bound generically and at indexed slots the
  // kernels use (0 uniform, 1.. storage).
  const char* src = "#version 430\nlayout(local_size_x = 1) in;\nvoid main() {}\n";
  GLuint shader = glCreateShader(GL_COMPUTE_SHADER);
  glShaderSource(shader, 1, &src, nullptr);
  glCompileShader(shader);
  GLuint program = glCreateProgram();
  glAttachShader(program, shader);
  glLinkProgram(program);
  glUseProgram(program);
  GLuint vao = 0, bufs[4];
  glGenVertexArrays(1, &vao);
  glBindVertexArray(vao);
  glGenBuffers(4, bufs);
  for (GLuint b : bufs) {
    glBindBuffer(GL_ARRAY_BUFFER, b);
    glBufferData(GL_ARRAY_BUFFER, 4096, nullptr, GL_STATIC_DRAW);
  }
  glBindBufferRange(GL_UNIFORM_BUFFER, 0, bufs[0], 256, 512);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, bufs[1]);
  glBindBufferRange(GL_SHADER_STORAGE_BUFFER, 2, bufs[2], 0, 1024);
  glBindBuffer(GL_SHADER_STORAGE_BUFFER, bufs[3]);
  glBindBuffer(GL_UNIFORM_BUFFER, bufs[2]);
  glBindBuffer(GL_COPY_READ_BUFFER, bufs[1]);
  glBindBuffer(GL_COPY_WRITE_BUFFER, bufs[0]);
  glBindBuffer(GL_ARRAY_BUFFER, bufs[3]);
  ASSERT_EQ(glGetError(), GLenum(GL_NO_ERROR));
  std::vector<GLint64> before = glBindings();

  Job j = strictJob();
  {
    std::unique_ptr<Backend> b = gl::createBackendOn(gl::adoptCurrentContext(glfwGetProcAddress));
    EXPECT_EQ(b->info().provider, "adopted");
    expectStrictSession(*b, j);
    EXPECT_EQ(glfwGetCurrentContext(), window);
    EXPECT_EQ(glBindings(), before);

    // Not current: refused, never made current by sffd.
    glfwMakeContextCurrent(nullptr);
    EXPECT_THROW(b->finish(), Error);
    EXPECT_EQ(glfwGetCurrentContext(), nullptr);
    glfwMakeContextCurrent(window);
    b->finish();
  }
  EXPECT_EQ(glBindings(), before);
  EXPECT_EQ(glfwGetCurrentContext(), window);
  glDeleteBuffers(4, bufs);
  glDeleteVertexArrays(1, &vao);
  glDeleteProgram(program);
  glDeleteShader(shader);
  glfwDestroyWindow(window);
  glfwTerminate();
}

// The other window system: an EGL surfaceless context (made here by sffd's provider, then treated
// as the application's), recognised through libEGL's eglGetCurrentContext.
TEST(GlInterop, AdoptedEglContextIsCheckedThroughEgl) {
  std::unique_ptr<gl::Context> egl;
  try {
    egl = gl::createEglContext();   // current on return
  } catch (const Error& e) {
    GTEST_SKIP() << e.what();
  }
  void* lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_NOLOAD);
  ASSERT_NE(lib, nullptr);
  auto getProc = reinterpret_cast<gl::GLProc (*)(const char*)>(dlsym(lib, "eglGetProcAddress"));
  Job j = strictJob();
  std::unique_ptr<Backend> b = gl::createBackendOn(gl::adoptCurrentContext(getProc));
  expectStrictSession(*b, j);
  egl->activate();   // sffd's own context object: the same EGL context, still current
  b->finish();
  // The application makes nothing current: refused. (sffd's deactivateCurrent() would not do it:
  // it never releases an adopted context.)
  auto display = reinterpret_cast<void* (*)()>(dlsym(lib, "eglGetCurrentDisplay"))();
  auto makeCurrent = reinterpret_cast<unsigned (*)(void*, void*, void*, void*)>(dlsym(lib, "eglMakeCurrent"));
  gl::Context::deactivateCurrent();
  b->finish();
  ASSERT_TRUE(makeCurrent(display, nullptr, nullptr, nullptr));
  EXPECT_THROW(b->finish(), Error);
  egl->activate();
  b->finish();
  b.reset();
  dlclose(lib);
}

// An application's OpenGL ES context (made here by sffd's egl-es provider, then treated as the
// application's), adopted through the public API: a gles device, held to the ES 3.1 minimum limits
// unless SFFD_GLES_LIMITS=device, that runs the strict session to the CPU reference's bits either way.
TEST(GlInterop, AdoptedEsContextIsAGlesDevice) {
  std::unique_ptr<gl::Context> es;
  try {
    es = gl::createEglEsContext();   // current on return
  } catch (const Error& e) {
    GTEST_SKIP() << e.what();
  }
  void* lib = dlopen("libEGL.so.1", RTLD_NOW | RTLD_NOLOAD);
  ASSERT_NE(lib, nullptr);
  auto getProc = reinterpret_cast<sffd::opengl::GetProcAddress>(dlsym(lib, "eglGetProcAddress"));
  Job j = strictJob();
  {
    Device held = sffd::opengl::adoptCurrentContext(getProc);
    EXPECT_EQ(held.label(), "gles-adopted");
    EXPECT_EQ(held.info().api, "gles");
    EXPECT_FALSE(held.info().limits.float64);
    // Every kernel fits the ES 3.1 minimum limits (gles_limits_test.cc).
    expectStrictSession(held.backend(), j);
  }
  setenv("SFFD_GLES_LIMITS", "device", 1);
  Device own = sffd::opengl::adoptCurrentContext(getProc);
  unsetenv("SFFD_GLES_LIMITS");
  expectStrictSession(own.backend(), j);
  dlclose(lib);
}

}  // namespace
