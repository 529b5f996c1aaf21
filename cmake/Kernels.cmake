# Compiles every kernel in shaders/ to SPIR-V in four variants (strict x f64) with glslangValidator,
# tracked by depfiles, and embeds them with the include-inlined GLSL into one generated C++ file.
# Add a kernel by adding its stem to SFFD_KERNELS.
set(SFFD_KERNELS classic_ffd pn_triangles clip_count clip_write deform_smooth
    deform_step_sample deform_step_fit deform_step_adjust deform_step_tessellate)
# accurate FFD (src/core/accurate_ffd.cpp):
list(APPEND SFFD_KERNELS accurate_patches)

set(SFFD_SHADER_DIR ${CMAKE_SOURCE_DIR}/shaders)
set(SFFD_SPV_DIR ${CMAKE_BINARY_DIR}/spv)
file(MAKE_DIRECTORY ${SFFD_SPV_DIR})
file(GLOB SFFD_SHADER_COMMON CONFIGURE_DEPENDS ${SFFD_SHADER_DIR}/common/*)

add_executable(embed_kernels tools/embed_kernels.cpp)

set(_spv_outputs)
foreach(kernel IN LISTS SFFD_KERNELS)
  foreach(v 0 1 2 3)
    math(EXPR strict "${v} % 2")
    math(EXPR f64 "${v} / 2")
    set(out ${SFFD_SPV_DIR}/${kernel}.v${v}.spv)
    add_custom_command(
      OUTPUT ${out}
      COMMAND Vulkan::glslangValidator -V --target-env vulkan1.1 --quiet
              -DSFFD_STRICT=${strict} -DSFFD_F64=${f64}
              --depfile ${out}.d -o ${out} ${SFFD_SHADER_DIR}/${kernel}.comp
      DEPENDS ${SFFD_SHADER_DIR}/${kernel}.comp
      DEPFILE ${out}.d
      COMMENT "glslang: ${kernel} variant ${v}"
      VERBATIM)
    list(APPEND _spv_outputs ${out})
  endforeach()
endforeach()

set(SFFD_KERNELS_CPP ${CMAKE_BINARY_DIR}/generated/kernels_embedded.cpp)
add_custom_command(
  OUTPUT ${SFFD_KERNELS_CPP}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${CMAKE_BINARY_DIR}/generated
  COMMAND embed_kernels ${SFFD_KERNELS_CPP} ${SFFD_SHADER_DIR} ${SFFD_SPV_DIR} ${SFFD_KERNELS}
  DEPENDS embed_kernels ${_spv_outputs} ${SFFD_SHADER_COMMON}
  COMMENT "Embedding kernels"
  VERBATIM)
