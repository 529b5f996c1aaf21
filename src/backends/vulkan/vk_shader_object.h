// VK_EXT_shader_object, as far as sffd uses it: compute shaders made from SPIR-V or from a binary the
// driver gave back earlier (the shader binary cache, core/shader_binary_cache.h). Declared here when
// the Vulkan headers predate the extension (1.3.246; Debian 12 has 1.3.239); values from its registry.
#pragma once
#include "backends/vulkan/vk_loader.h"

#ifndef VK_EXT_shader_object
#define VK_EXT_shader_object 1
VK_DEFINE_NON_DISPATCHABLE_HANDLE(VkShaderEXT)
typedef enum VkShaderCodeTypeEXT { VK_SHADER_CODE_TYPE_BINARY_EXT = 0, VK_SHADER_CODE_TYPE_SPIRV_EXT = 1 } VkShaderCodeTypeEXT;
typedef VkFlags VkShaderCreateFlagsEXT;
#define VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_OBJECT_FEATURES_EXT ((VkStructureType)1000482000)
#define VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SHADER_OBJECT_PROPERTIES_EXT ((VkStructureType)1000482001)
#define VK_STRUCTURE_TYPE_SHADER_CREATE_INFO_EXT ((VkStructureType)1000482002)
typedef struct VkPhysicalDeviceShaderObjectFeaturesEXT {
  VkStructureType sType;
  void* pNext;
  VkBool32 shaderObject;
} VkPhysicalDeviceShaderObjectFeaturesEXT;
typedef struct VkPhysicalDeviceShaderObjectPropertiesEXT {
  VkStructureType sType;
  void* pNext;
  uint8_t shaderBinaryUUID[VK_UUID_SIZE];
  uint32_t shaderBinaryVersion;
} VkPhysicalDeviceShaderObjectPropertiesEXT;
typedef struct VkShaderCreateInfoEXT {
  VkStructureType sType;
  const void* pNext;
  VkShaderCreateFlagsEXT flags;
  VkShaderStageFlagBits stage;
  VkShaderStageFlags nextStage;
  VkShaderCodeTypeEXT codeType;
  size_t codeSize;
  const void* pCode;
  const char* pName;
  uint32_t setLayoutCount;
  const VkDescriptorSetLayout* pSetLayouts;
  uint32_t pushConstantRangeCount;
  const VkPushConstantRange* pPushConstantRanges;
  const VkSpecializationInfo* pSpecializationInfo;
} VkShaderCreateInfoEXT;
typedef VkResult(VKAPI_PTR* PFN_vkCreateShadersEXT)(VkDevice device, uint32_t createInfoCount,
                                                    const VkShaderCreateInfoEXT* pCreateInfos,
                                                    const VkAllocationCallbacks* pAllocator, VkShaderEXT* pShaders);
typedef void(VKAPI_PTR* PFN_vkDestroyShaderEXT)(VkDevice device, VkShaderEXT shader, const VkAllocationCallbacks* pAllocator);
typedef VkResult(VKAPI_PTR* PFN_vkGetShaderBinaryDataEXT)(VkDevice device, VkShaderEXT shader, size_t* pDataSize, void* pData);
typedef void(VKAPI_PTR* PFN_vkCmdBindShadersEXT)(VkCommandBuffer commandBuffer, uint32_t stageCount,
                                                 const VkShaderStageFlagBits* pStages, const VkShaderEXT* pShaders);
#endif

namespace sffd::vk {

// The extension's entry points and the identity of its binaries, on a device that enabled it.
struct ShaderObjects {
  PFN_vkCreateShadersEXT vkCreateShadersEXT = nullptr;
  PFN_vkDestroyShaderEXT vkDestroyShaderEXT = nullptr;
  PFN_vkGetShaderBinaryDataEXT vkGetShaderBinaryDataEXT = nullptr;
  PFN_vkCmdBindShadersEXT vkCmdBindShadersEXT = nullptr;
  // Binaries are interchangeable between devices whose driver reports the same pair.
  uint8_t binaryUuid[VK_UUID_SIZE] = {};
  uint32_t binaryVersion = 0;
};

}  // namespace sffd::vk
