# Compiles every kernel in kernels/<stage>/ to SPIR-V in four variants (strict x f64) with
# glslangValidator, tracked by depfiles; writes its OpenGL ES form ("#version 310 es", f32 only) and
# checks it with glslang against the ES 3.1 rules in both float variants; and embeds them with the
# include-inlined GLSL into one generated C++ file (src/core/kernel_registry.h). Add a kernel by adding STAGE/STEM to SFFD_KERNELS;
# it is registered under its stem.
set(SFFD_KERNELS
    classic/classic_ffd
    pn/pn_triangles
    clip/clip_count clip/clip_write
    smooth/deform_smooth
    smooth/deform_step_sample smooth/deform_step_fit smooth/deform_step_adjust smooth/deform_step_tessellate
    accurate/accurate_patches)

set(SFFD_KERNEL_DIR ${PROJECT_SOURCE_DIR}/kernels)
set(SFFD_SPV_DIR ${PROJECT_BINARY_DIR}/spv)
set(SFFD_GLES_DIR ${PROJECT_BINARY_DIR}/gles)
file(MAKE_DIRECTORY ${SFFD_SPV_DIR} ${SFFD_GLES_DIR})
file(GLOB SFFD_KERNEL_INCLUDES CONFIGURE_DEPENDS ${SFFD_KERNEL_DIR}/*/*.glsl ${SFFD_KERNEL_DIR}/common/layout.h)

add_executable(embed_kernels ${PROJECT_SOURCE_DIR}/tools/embed_kernels.cpp)
target_compile_options(embed_kernels PRIVATE ${SFFD_WARNINGS})

set(_spv_outputs)
foreach(kernel IN LISTS SFFD_KERNELS)
  get_filename_component(stem ${kernel} NAME)
  foreach(v 0 1 2 3)
    math(EXPR strict "${v} % 2")
    math(EXPR f64 "${v} / 2")
    set(out ${SFFD_SPV_DIR}/${stem}.v${v}.spv)
    add_custom_command(
      OUTPUT ${out}
      COMMAND Vulkan::glslangValidator -V --target-env vulkan1.1 --quiet
              -DSFFD_STRICT=${strict} -DSFFD_F64=${f64}
              --depfile ${out}.d -o ${out} ${SFFD_KERNEL_DIR}/${kernel}.comp
      DEPENDS ${SFFD_KERNEL_DIR}/${kernel}.comp
      DEPFILE ${out}.d
      COMMENT "glslang: ${stem} variant ${v}"
      VERBATIM)
    list(APPEND _spv_outputs ${out})
  endforeach()
  set(es ${SFFD_GLES_DIR}/${stem}.comp)
  add_custom_command(
    OUTPUT ${es}
    COMMAND embed_kernels --es ${es} ${SFFD_KERNEL_DIR}/${kernel}.comp
    COMMAND Vulkan::glslangValidator --quiet -l -DSFFD_STRICT=0 -DSFFD_F64=0 ${es}
    COMMAND Vulkan::glslangValidator --quiet -l -DSFFD_STRICT=1 -DSFFD_F64=0 ${es}
    DEPENDS embed_kernels ${SFFD_KERNEL_DIR}/${kernel}.comp ${SFFD_KERNEL_INCLUDES}
    COMMENT "glslang: ${stem} as OpenGL ES 3.1"
    VERBATIM)
  list(APPEND _spv_outputs ${es})
endforeach()

set(SFFD_KERNELS_CPP ${PROJECT_BINARY_DIR}/generated/kernels_embedded.cpp)
add_custom_command(
  OUTPUT ${SFFD_KERNELS_CPP}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/generated
  COMMAND embed_kernels ${SFFD_KERNELS_CPP} ${SFFD_KERNEL_DIR} ${SFFD_SPV_DIR} ${SFFD_GLES_DIR} ${SFFD_KERNELS}
  DEPENDS embed_kernels ${_spv_outputs} ${SFFD_KERNEL_INCLUDES}
  COMMENT "Embedding kernels"
  VERBATIM)
