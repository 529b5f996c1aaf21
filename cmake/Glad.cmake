# Generates the glad loaders at build time from python3-glad's bundled specs (no network): OpenGL 4.5
# core for the gl backends and OpenGL ES 3.1 for the gles backend, in one run. Function pointers are
# loaded per context through OSMesaGetProcAddress, eglGetProcAddress or glfwGetProcAddress, so the
# binary links no libGL or libGLESv2.
set(SFFD_GLAD_DIR ${PROJECT_BINARY_DIR}/glad)
add_custom_command(
  OUTPUT ${SFFD_GLAD_DIR}/src/gl.c ${SFFD_GLAD_DIR}/include/glad/gl.h
         ${SFFD_GLAD_DIR}/src/gles2.c ${SFFD_GLAD_DIR}/include/glad/gles2.h
  COMMAND ${GLAD_EXECUTABLE} --quiet --reproducible --api gl:core=4.5,gles2=3.1
          --extensions GL_ARB_gl_spirv,GL_ARB_spirv_extensions,GL_KHR_debug,GL_EXT_disjoint_timer_query,GL_KHR_parallel_shader_compile,GL_ARB_parallel_shader_compile
          --out-path ${SFFD_GLAD_DIR} c
  COMMAND ${CMAKE_COMMAND} -DHEADER=${SFFD_GLAD_DIR}/include/glad/gl.h -DGUARD=GLAD_GL_H_
          -P ${PROJECT_SOURCE_DIR}/cmake/GladPrefix.cmake
  COMMAND ${CMAKE_COMMAND} -DHEADER=${SFFD_GLAD_DIR}/include/glad/gles2.h -DGUARD=GLAD_GLES2_H_
          -DSHARE_WITH=${SFFD_GLAD_DIR}/src/gl.c -DSOURCE=${SFFD_GLAD_DIR}/src/gles2.c
          -P ${PROJECT_SOURCE_DIR}/cmake/GladPrefix.cmake
  DEPENDS ${PROJECT_SOURCE_DIR}/cmake/GladPrefix.cmake
  COMMENT "Generating the glad GL and GLES loaders"
  VERBATIM)
# An object library compiled into libsffd only: one copy of glad's entry-point table in any binary
# (the renderer and viewer use the library's). The ES loader fills the same table as the GL one.
add_library(sffd_glad OBJECT ${SFFD_GLAD_DIR}/src/gl.c ${SFFD_GLAD_DIR}/src/gles2.c)
target_include_directories(sffd_glad PUBLIC ${SFFD_GLAD_DIR}/include)
set_target_properties(sffd_glad PROPERTIES POSITION_INDEPENDENT_CODE ON)
