# Compiles every kernel in kernels/<stage>/ to SPIR-V in four variants (strict x f64) with
# glslangValidator, tracked by depfiles, optimizing those of SFFD_SPIRV_OPTIMIZED with spirv-opt, and
# the SFFD_SPECIALIZED_<stem> forms the same way; writes its OpenGL ES form ("#version 310 es", f32 only) and
# checks it with glslang against the ES 3.1 rules in both float variants; and embeds them with the
# include-inlined GLSL into one generated C++ file (src/core/kernel_registry.h). Add a kernel by adding
# STAGE/STEM to SFFD_KERNELS; it is registered under its stem.
set(SFFD_KERNELS
    classic/classic_ffd
    pn/pn_triangles
    clip/clip_count clip/clip_write
    smooth/deform_smooth
    smooth/deform_step_sample smooth/deform_step_fit smooth/deform_step_adjust smooth/deform_step_tessellate
    accurate/accurate_patches)

# spirv-opt's performance passes (`-O`) without its arithmetic simplification, for the kernels of
# SFFD_SPIRV_OPTIMIZED: lavapipe translates and optimizes each pipeline's SPIR-V in every process (its
# disk cache keeps only machine code), and deform_smooth's inlined SSA form with its assumptions folded
# is translated in 30-50 ms, not 100-260 (docs/performance/kernels.md, "SPIR-V made for the usual dispatch").
# clip_write's in 26 ms, not 35, for 6 % more instructions when it runs on lavapipe 22.3 (0.1 ms of a
# clip that runs once a mesh, against the translation every process pays: "The whole run, again");
# pn_triangles' in 5.8 ms, not 7.1, clip_count's in 2.6, not 3.8, their warm times within the noise
# ("The whole run, again", 2026-11-30). The others (split steps, accurate and classic FFD's), not
# measured so, stay as glslang writes them. `--simplify-instructions` is left out
# because it reassociates float constants where no NoContraction forbids it: the fast kernels would no
# longer give the CPU twin's bits on lavapipe. The rest changes no arithmetic (constant folding is IEEE;
# strict kernels stay bit-identical).
set(SFFD_SPIRV_OPTIMIZED deform_smooth clip_write pn_triangles clip_count)
find_program(SFFD_SPIRV_OPT spirv-opt REQUIRED)
set(SFFD_SPIRV_OPT_PASSES
    --wrap-opkill --eliminate-dead-branches --merge-return --inline-entry-points-exhaustive
    --eliminate-dead-functions --eliminate-dead-code-aggressive --private-to-local
    --eliminate-local-single-block --eliminate-local-single-store --eliminate-dead-code-aggressive
    --scalar-replacement --convert-local-access-chains --eliminate-local-single-block
    --eliminate-local-single-store --eliminate-dead-code-aggressive --eliminate-local-multi-store
    --eliminate-dead-code-aggressive --ccp --eliminate-dead-code-aggressive --loop-unroll
    --eliminate-dead-branches --redundancy-elimination --combine-access-chains --scalar-replacement
    --convert-local-access-chains --eliminate-local-single-block --eliminate-local-single-store
    --eliminate-dead-code-aggressive --ssa-rewrite --eliminate-dead-code-aggressive --vector-dce
    --eliminate-dead-inserts --eliminate-dead-branches --if-conversion --copy-propagate-arrays
    --reduce-load-size --eliminate-dead-code-aggressive --merge-blocks --redundancy-elimination
    --eliminate-dead-branches --merge-blocks)

set(SFFD_KERNEL_DIR ${PROJECT_SOURCE_DIR}/kernels)
set(SFFD_SPV_DIR ${PROJECT_BINARY_DIR}/spv)
set(SFFD_GLES_DIR ${PROJECT_BINARY_DIR}/gles)
file(MAKE_DIRECTORY ${SFFD_SPV_DIR} ${SFFD_GLES_DIR})
file(GLOB SFFD_KERNEL_INCLUDES CONFIGURE_DEPENDS ${SFFD_KERNEL_DIR}/*/*.glsl ${SFFD_KERNEL_DIR}/common/layout.h
     ${SFFD_KERNEL_DIR}/common/correctly_rounded.h)

add_executable(embed_kernels ${PROJECT_SOURCE_DIR}/tools/embed_kernels.cpp)
target_compile_options(embed_kernels PRIVATE ${SFFD_WARNINGS})

# Kernels also compiled for their most common dispatches, the assumptions (layout.h SFFD_ASSUME_*, named
# without the prefix) a constant as on GL rather than the specialization constant, so that the module
# lavapipe translates (above) holds that case only.
set(SFFD_SPECIALIZED_deform_smooth
    DEGREE2|LATTICE_IN_PARAMS|FIT_IN_PARAMS                    # degree 2, lattice and fit table in the parameter block
    DEGREE2|LATTICE_IN_PARAMS|FIT_IN_PARAMS|ROLLED_LOOPS       # the same on llvmpipe of Mesa 23 on (forDevice)
    DEGREE2|LATTICE_IN_PARAMS|FIT_IN_PARAMS|ONE_SAMPLE_SITE)   # a small one-shot job on lavapipe below Mesa 23
# The pre-compute's kernels have two loop forms (prelude.glsl sffdRollsLoops) and no other assumption:
# both compiled ahead (NONE: no bit), so that the form a driver does not use is not in its SPIR-V at all.
# With the choice left to the specialization constant, lavapipe 22.3 ran clip_write's straight form
# 9 to 25 % slower than the same code compiled alone (callgrind), and translated both forms.
set(SFFD_SPECIALIZED_pn_triangles NONE ROLLED_LOOPS)
set(SFFD_SPECIALIZED_clip_count NONE ROLLED_LOOPS)
set(SFFD_SPECIALIZED_clip_write NONE ROLLED_LOOPS)

set(_spv_outputs)
set(_embed_kernels)
foreach(kernel IN LISTS SFFD_KERNELS)
  get_filename_component(stem ${kernel} NAME)
  # One general module per variant, then one per specialization: "" or -DSFFD_ASSUMPTIONS=(...).
  set(forms g)
  set(embed_arg ${kernel})
  set(i 0)
  foreach(names IN LISTS SFFD_SPECIALIZED_${stem})
    if(names STREQUAL "NONE")
      set(expr "0u")
    else()
      string(REPLACE "|" "|SFFD_ASSUME_" expr "(SFFD_ASSUME_${names})")
    endif()
    set(define_s${i} -DSFFD_ASSUMPTIONS=${expr})
    list(APPEND forms s${i})
    string(APPEND embed_arg ":${expr}")
    math(EXPR i "${i} + 1")
  endforeach()
  list(APPEND _embed_kernels ${embed_arg})
  foreach(form IN LISTS forms)
    foreach(v 0 1 2 3)
      math(EXPR strict "${v} % 2")
      math(EXPR f64 "${v} / 2")
      if(form STREQUAL "g")
        set(out ${SFFD_SPV_DIR}/${stem}.v${v}.spv)
        set(define)
      else()
        set(out ${SFFD_SPV_DIR}/${stem}.v${v}.${form}.spv)
        set(define ${define_${form}})
      endif()
      set(optimize)
      if(stem IN_LIST SFFD_SPIRV_OPTIMIZED)
        set(optimize COMMAND ${SFFD_SPIRV_OPT} ${SFFD_SPIRV_OPT_PASSES} --target-env=vulkan1.1 ${out} -o ${out})
      endif()
      add_custom_command(
        OUTPUT ${out}
        COMMAND Vulkan::glslangValidator -V --target-env vulkan1.1 --quiet
                -DSFFD_STRICT=${strict} -DSFFD_F64=${f64} ${define}
                --depfile ${out}.d -o ${out} ${SFFD_KERNEL_DIR}/${kernel}.comp
        ${optimize}
        DEPENDS ${SFFD_KERNEL_DIR}/${kernel}.comp
        DEPFILE ${out}.d
        COMMENT "glslang: ${stem} variant ${v} ${form}"
        VERBATIM)
      list(APPEND _spv_outputs ${out})
    endforeach()
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
  COMMAND embed_kernels ${SFFD_KERNELS_CPP} ${SFFD_KERNEL_DIR} ${SFFD_SPV_DIR} ${SFFD_GLES_DIR} ${_embed_kernels}
  DEPENDS embed_kernels ${_spv_outputs} ${SFFD_KERNEL_INCLUDES}
  COMMENT "Embedding kernels"
  VERBATIM)
