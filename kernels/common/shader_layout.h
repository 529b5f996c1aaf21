// C++ view of kernels/common/layout.h: maps its GLSL type words onto plain C++ structs
// whose layout equals std140 for the member types the layout file allows.
#pragma once
#include <cstdint>

namespace sffd::gpu {
struct alignas(16) Vec4 { float x = 0, y = 0, z = 0, w = 0; };
struct alignas(16) UVec4 { uint32_t x = 0, y = 0, z = 0, w = 0; };
struct alignas(16) IVec4 { int32_t x = 0, y = 0, z = 0, w = 0; };

#define SFFD_VEC4 ::sffd::gpu::Vec4
#define SFFD_UVEC4 ::sffd::gpu::UVec4
#define SFFD_IVEC4 ::sffd::gpu::IVec4
#define SFFD_STRUCT_BEGIN(name) struct name {
#define SFFD_STRUCT_MEMBER(type, member) type member;
#define SFFD_STRUCT_END(name) }; static_assert(sizeof(name) % 16 == 0, #name " must be a whole number of vec4");
#include "layout.h"
#undef SFFD_STRUCT_BEGIN
#undef SFFD_STRUCT_MEMBER
#undef SFFD_STRUCT_END
}  // namespace sffd::gpu
