// The OpenGL ES 3.1 minimum limits (ES 3.1 specification, table 20.45 onwards) that many phones sit
// at. The gles backend holds itself to them unless asked for the device's own (gl::Options,
// SFFD_GLES_LIMITS=device), so that passing here means passing on a minimum device.
#pragma once
#include <cstdint>

namespace sffd::gl::es31 {

constexpr int kMaxComputeStorageBlocks = 4;        // GL_MAX_COMPUTE_SHADER_STORAGE_BLOCKS
constexpr int kMaxStorageBindings = 4;             // GL_MAX_SHADER_STORAGE_BUFFER_BINDINGS
constexpr int kMaxUniformBlockSize = 16384;        // GL_MAX_UNIFORM_BLOCK_SIZE, bytes
constexpr int kMaxSharedMemory = 16384;            // GL_MAX_COMPUTE_SHARED_MEMORY_SIZE, bytes
constexpr int kMaxInvocations = 128;               // GL_MAX_COMPUTE_WORK_GROUP_INVOCATIONS
constexpr int kMaxGroupSize[3] = {128, 128, 64};   // GL_MAX_COMPUTE_WORK_GROUP_SIZE
constexpr uint32_t kMaxGroupCount = 65535;         // GL_MAX_COMPUTE_WORK_GROUP_COUNT, each axis
constexpr uint64_t kMaxStorageBlockSize = 1u << 27;   // GL_MAX_SHADER_STORAGE_BLOCK_SIZE, bytes

}  // namespace sffd::gl::es31
