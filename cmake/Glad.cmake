# Generates the glad GL 4.5 core loader at build time from python3-glad's bundled specs (no network).
# Function pointers are loaded per context through OSMesaGetProcAddress, eglGetProcAddress or
# glfwGetProcAddress, so the binary links no libGL.
set(SFFD_GLAD_DIR ${PROJECT_BINARY_DIR}/glad)
add_custom_command(
  OUTPUT ${SFFD_GLAD_DIR}/src/gl.c ${SFFD_GLAD_DIR}/include/glad/gl.h
  COMMAND ${GLAD_EXECUTABLE} --quiet --reproducible --api gl:core=4.5
          --extensions GL_ARB_gl_spirv,GL_ARB_spirv_extensions,GL_KHR_debug
          --out-path ${SFFD_GLAD_DIR} c
  COMMAND ${CMAKE_COMMAND} -DHEADER=${SFFD_GLAD_DIR}/include/glad/gl.h -P ${PROJECT_SOURCE_DIR}/cmake/GladPrefix.cmake
  DEPENDS ${PROJECT_SOURCE_DIR}/cmake/GladPrefix.cmake
  COMMENT "Generating the glad GL loader"
  VERBATIM)
# An object library compiled into libsffd only: one copy of glad's entry-point table in any binary
# (the renderer and viewer use the library's).
add_library(sffd_glad OBJECT ${SFFD_GLAD_DIR}/src/gl.c)
target_include_directories(sffd_glad PUBLIC ${SFFD_GLAD_DIR}/include)
set_target_properties(sffd_glad PROPERTIES POSITION_INDEPENDENT_CODE ON)
