# Generates the crack-free split-pattern table (METHOD.md 4.2) at build time with
# tools/split_pattern_gen.cpp; the generated source is compiled into sffd_core
# (kernels/clip/split_pattern_table.h). See docs/SPLIT_PATTERNS.md.
set(SFFD_SPLIT_NMAX 24 CACHE STRING "Largest per-edge segment count of the split-pattern table (24 or more)")
if(NOT SFFD_SPLIT_NMAX MATCHES "^[0-9]+$" OR SFFD_SPLIT_NMAX LESS 24 OR SFFD_SPLIT_NMAX GREATER 200)
  message(FATAL_ERROR "SFFD_SPLIT_NMAX must be an integer in 24..200, not '${SFFD_SPLIT_NMAX}'")
endif()

add_executable(split_pattern_gen ${PROJECT_SOURCE_DIR}/tools/split_pattern_gen.cpp)
target_include_directories(split_pattern_gen PRIVATE ${PROJECT_SOURCE_DIR})
# Runs on every clean build: optimised in Debug builds too (0.5 s instead of 5; same output bytes).
target_compile_options(split_pattern_gen PRIVATE $<$<CXX_COMPILER_ID:GNU,Clang>:-O2>)

set(SFFD_SPLIT_PATTERNS_CPP ${PROJECT_BINARY_DIR}/generated/split_patterns.cpp)
add_custom_command(
  OUTPUT ${SFFD_SPLIT_PATTERNS_CPP}
  COMMAND ${CMAKE_COMMAND} -E make_directory ${PROJECT_BINARY_DIR}/generated
  COMMAND split_pattern_gen --nmax ${SFFD_SPLIT_NMAX} ${SFFD_SPLIT_PATTERNS_CPP}
  DEPENDS split_pattern_gen
  COMMENT "Generating split patterns (Nmax ${SFFD_SPLIT_NMAX})"
  VERBATIM)
