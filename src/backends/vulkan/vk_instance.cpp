#include "backends/vulkan/vk_instance.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstring>
#include <iterator>

#include <sffd/error.h>
#include "kernels/common/shader_layout.h"
#include "backends/vulkan/vk_backend.h"

namespace sffd::vk {

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

std::atomic<size_t> gValidationMessages{0};

// Prints every warning and error; counts those of the validation layer (type VALIDATION or
// PERFORMANCE). GENERAL messages come from the loader itself (e.g. "no ICD found" while probing
// a machine without Vulkan): printed only with SFFD_VK_VERBOSE=1, and never counted.
VKAPI_ATTR VkBool32 VKAPI_CALL onDebugMessage(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                              VkDebugUtilsMessageTypeFlagsEXT type,
                                              const VkDebugUtilsMessengerCallbackDataEXT* data, void*) {
  const bool error = severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  if (type & (VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT))
    ++gValidationMessages;
  // The loader's own chatter stays quiet unless asked for: a failed probe ends in one device Error
  // line of sffd's, which names the problem (the contract's one-line errors).
  else if (!envFlag("SFFD_VK_VERBOSE"))
    return VK_FALSE;
  std::fprintf(stderr, "sffd: vulkan %s: %s\n", error ? "error" : "warning", data && data->pMessage ? data->pMessage : "");
  return VK_FALSE;   // never abort the call that triggered it
}

VkDebugUtilsMessengerCreateInfoEXT messengerInfo() {
  auto info = vkStruct<VkDebugUtilsMessengerCreateInfoEXT>(VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT);
  info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                     VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  info.pfnUserCallback = onDebugMessage;
  return info;
}

// The layer's specVersion (the Vulkan headers it was built with); 0 when it is not installed.
uint32_t layerVersion(const Api& api, const char* name) {
  uint32_t count = 0;
  api.vkEnumerateInstanceLayerProperties(&count, nullptr);
  std::vector<VkLayerProperties> layers(count);
  api.vkEnumerateInstanceLayerProperties(&count, layers.data());
  for (const VkLayerProperties& l : layers)
    if (std::strcmp(l.layerName, name) == 0) return std::max(l.specVersion, 1u);
  return 0;
}

// Instance extensions of the implementation and implicit layers, plus those of `layer` if given.
bool hasInstanceExtension(const Api& api, const char* name, const char* layer = nullptr) {
  uint32_t count = 0;
  api.vkEnumerateInstanceExtensionProperties(layer, &count, nullptr);
  std::vector<VkExtensionProperties> exts(count);
  api.vkEnumerateInstanceExtensionProperties(layer, &count, exts.data());
  for (const VkExtensionProperties& e : exts)
    if (std::strcmp(e.extensionName, name) == 0) return true;
  return false;
}

std::string versionString(uint32_t v) {
  return std::to_string(VK_API_VERSION_MAJOR(v)) + "." + std::to_string(VK_API_VERSION_MINOR(v)) + "." +
         std::to_string(VK_API_VERSION_PATCH(v));
}

int typeRank(VkPhysicalDeviceType type) {
  switch (type) {
    case VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU: return 0;
    case VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU: return 1;
    case VK_PHYSICAL_DEVICE_TYPE_VIRTUAL_GPU: return 2;
    case VK_PHYSICAL_DEVICE_TYPE_CPU: return 3;
    default: return 4;
  }
}

// DeviceInfo::type, indexed by typeRank().
constexpr const char* kTypeNames[] = {"discrete", "integrated", "virtual", "cpu", "other"};

PhysicalDevice describe(const Api& api, VkPhysicalDevice handle) {
  PhysicalDevice pd;
  pd.handle = handle;
  VkPhysicalDeviceProperties props;
  api.vkGetPhysicalDeviceProperties(handle, &props);
  VkPhysicalDeviceFeatures features;
  api.vkGetPhysicalDeviceFeatures(handle, &features);

  DeviceInfo& info = pd.info;
  info.api = "vulkan";
  info.provider = "vulkan";
  info.name = props.deviceName;
  info.type = kTypeNames[typeRank(props.deviceType)];
  info.driver = "Vulkan " + versionString(props.apiVersion) + ", driver version " + std::to_string(props.driverVersion);
  info.vendorId = props.vendorID;
  info.deviceId = props.deviceID;
  info.driverVersion = std::to_string(props.driverVersion);
  if (props.apiVersion >= VK_API_VERSION_1_1) {   // VkPhysicalDeviceIDProperties is core in 1.1
    auto ids = vkStruct<VkPhysicalDeviceIDProperties>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ID_PROPERTIES);
    auto props2 = vkStruct<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
    props2.pNext = &ids;
    api.vkGetPhysicalDeviceProperties2(handle, &props2);
    static const char* hex = "0123456789abcdef";
    for (uint8_t b : ids.deviceUUID) info.uuid += hex[b >> 4], info.uuid += hex[b & 15];
  }
  // Driver name and info are core in 1.2 and VK_KHR_driver_properties before.
  if (props.apiVersion >= VK_API_VERSION_1_2 || hasDeviceExtension(api, handle, "VK_KHR_driver_properties")) {
    auto driver = vkStruct<VkPhysicalDeviceDriverProperties>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES);
    auto props2 = vkStruct<VkPhysicalDeviceProperties2>(VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2);
    props2.pNext = &driver;
    api.vkGetPhysicalDeviceProperties2(handle, &props2);
    info.driver = std::string(driver.driverName) + " " + driver.driverInfo + ", Vulkan " + versionString(props.apiVersion);
    if (driver.driverInfo[0]) info.driverVersion = driver.driverInfo;   // "Mesa 22.3.6" rather than an encoded number
  }

  uint32_t familyCount = 0;
  api.vkGetPhysicalDeviceQueueFamilyProperties(handle, &familyCount, nullptr);
  std::vector<VkQueueFamilyProperties> families(familyCount);
  api.vkGetPhysicalDeviceQueueFamilyProperties(handle, &familyCount, families.data());
  for (uint32_t i = 0; i < familyCount; ++i)
    if (families[i].queueFlags & VK_QUEUE_COMPUTE_BIT) {
      pd.computeFamily = i;
      pd.timestampBits = families[i].timestampValidBits;
      break;
    }

  DeviceLimits& limits = info.limits;
  limits.maxStorageBufferRange = props.limits.maxStorageBufferRange;
  limits.storageOffsetAlignment = props.limits.minStorageBufferOffsetAlignment;
  for (int i = 0; i < 3; ++i) limits.maxWorkGroupCount[i] = props.limits.maxComputeWorkGroupCount[i];
  // SFFD_VK_DISABLE_F64=1 hides shaderFloat64, to test the refusal of f64 kernels on any device.
  limits.float64 = features.shaderFloat64 && !envFlag("SFFD_VK_DISABLE_F64");
  limits.timestamps = props.limits.timestampComputeAndGraphics && props.limits.timestampPeriod > 0 && pd.timestampBits > 0;

  if (props.apiVersion < VK_API_VERSION_1_1)
    pd.unusable = "it supports only Vulkan " + versionString(props.apiVersion) + " (1.1 is required)";
  else if (pd.computeFamily == UINT32_MAX)
    pd.unusable = "it has no compute queue";
  else if (props.limits.maxPerStageDescriptorStorageBuffers < SFFD_MAX_STORAGE_BINDINGS)
    pd.unusable = "it allows only " + std::to_string(props.limits.maxPerStageDescriptorStorageBuffers) +
                  " storage buffers per kernel";
  return pd;
}

}  // namespace

bool hasDeviceExtension(const Api& api, VkPhysicalDevice device, const char* name) {
  uint32_t count = 0;
  api.vkEnumerateDeviceExtensionProperties(device, nullptr, &count, nullptr);
  std::vector<VkExtensionProperties> exts(count);
  api.vkEnumerateDeviceExtensionProperties(device, nullptr, &count, exts.data());
  for (const VkExtensionProperties& e : exts)
    if (std::strcmp(e.extensionName, name) == 0) return true;
  return false;
}

bool validationRequested(bool option) {
  return option || envFlag("SFFD_VK_VALIDATION");
}

Instance::Instance(bool validation) : api_(Api::load()) {
  uint32_t loaderVersion = VK_API_VERSION_1_0;
  if (api_.vkEnumerateInstanceVersion) api_.vkEnumerateInstanceVersion(&loaderVersion);
  if (loaderVersion < VK_API_VERSION_1_1)
    throw deviceError("Vulkan is not usable: the loader supports Vulkan " + versionString(loaderVersion) +
                      " and sffd needs 1.1.");

  std::vector<const char*> layers, extensions;
  bool debugUtils = false;
  if (validation) {
    if ((validationLayerVersion_ = layerVersion(api_, kValidationLayer)) != 0) {
      layers.push_back(kValidationLayer);
      debugUtils = hasInstanceExtension(api_, VK_EXT_DEBUG_UTILS_EXTENSION_NAME) ||
                   hasInstanceExtension(api_, VK_EXT_DEBUG_UTILS_EXTENSION_NAME, kValidationLayer);
      if (debugUtils) extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
    } else {
      std::fprintf(stderr, "sffd: warning: Vulkan validation requested but %s is not installed; running without it\n",
                   kValidationLayer);
    }
  }
  // Lets the loader report devices that implement only a subset of Vulkan (MoltenVK on macOS).
  VkInstanceCreateFlags flags = 0;
  if (hasInstanceExtension(api_, VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME)) {
    extensions.push_back(VK_KHR_PORTABILITY_ENUMERATION_EXTENSION_NAME);
    flags |= VK_INSTANCE_CREATE_ENUMERATE_PORTABILITY_BIT_KHR;
  }

  auto app = vkStruct<VkApplicationInfo>(VK_STRUCTURE_TYPE_APPLICATION_INFO);
  app.pApplicationName = "sffd";
  app.pEngineName = "sffd";
  // 1.2 when the loader has it, so that 1.2 physical-device queries (driver properties) are allowed.
  app.apiVersion = loaderVersion >= VK_API_VERSION_1_2 ? VK_API_VERSION_1_2 : VK_API_VERSION_1_1;

  auto ci = vkStruct<VkInstanceCreateInfo>(VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO);
  ci.flags = flags;
  ci.pApplicationInfo = &app;
  ci.enabledLayerCount = uint32_t(layers.size());
  ci.ppEnabledLayerNames = layers.data();
  ci.enabledExtensionCount = uint32_t(extensions.size());
  ci.ppEnabledExtensionNames = extensions.data();
  // Chained messenger: also reports problems inside vkCreateInstance / vkDestroyInstance.
  VkDebugUtilsMessengerCreateInfoEXT chained = messengerInfo();
  if (debugUtils) ci.pNext = &chained;

  VkResult r = api_.vkCreateInstance(&ci, nullptr, &instance_);
  if (r == VK_ERROR_INCOMPATIBLE_DRIVER)
    throw deviceError("Vulkan is not usable: no Vulkan driver (ICD) is installed or none supports Vulkan 1.1.");
  check(r, "vkCreateInstance");

  try {
    api_.loadInstance(instance_, debugUtils);
    if (debugUtils) {
      VkDebugUtilsMessengerCreateInfoEXT info = messengerInfo();
      check(api_.vkCreateDebugUtilsMessengerEXT(instance_, &info, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
    }
  } catch (...) {
    if (api_.vkDestroyInstance) api_.vkDestroyInstance(instance_, nullptr);
    throw;
  }
}

Instance::Instance(VkInstance borrowed, PFN_vkGetInstanceProcAddr getProc)
    : api_(getProc ? Api::borrow(getProc) : Api::load()), instance_(borrowed), owned_(false) {
  if (!borrowed) throw deviceError("Vulkan: adoptDevice needs the application's VkInstance");
  api_.loadInstance(instance_, false);
}

Instance::~Instance() {
  if (!owned_) return;
  if (messenger_) api_.vkDestroyDebugUtilsMessengerEXT(instance_, messenger_, nullptr);
  api_.vkDestroyInstance(instance_, nullptr);
}

PhysicalDevice Instance::describe(VkPhysicalDevice handle) const { return vk::describe(api_, handle); }

std::vector<PhysicalDevice> Instance::physicalDevices() const {
  uint32_t count = 0;
  VkResult r = api_.vkEnumeratePhysicalDevices(instance_, &count, nullptr);
  if (r == VK_ERROR_INITIALIZATION_FAILED || (r >= 0 && count == 0))
    throw deviceError("Vulkan is not usable: no Vulkan device was found.");
  check(r, "vkEnumeratePhysicalDevices");
  std::vector<VkPhysicalDevice> handles(count);
  check(api_.vkEnumeratePhysicalDevices(instance_, &count, handles.data()), "vkEnumeratePhysicalDevices");
  handles.resize(count);

  std::vector<PhysicalDevice> devices;
  for (VkPhysicalDevice h : handles) devices.push_back(describe(h));
  auto rank = [](const PhysicalDevice& d) {
    return std::find(std::begin(kTypeNames), std::end(kTypeNames), d.info.type) - std::begin(kTypeNames);
  };
  std::stable_sort(devices.begin(), devices.end(),
                   [&](const PhysicalDevice& a, const PhysicalDevice& b) { return rank(a) < rank(b); });
  return devices;
}

size_t validationMessageCount() { return gValidationMessages.load(); }

}  // namespace sffd::vk
