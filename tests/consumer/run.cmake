# The install test: installs the build tree into a fresh prefix, checks what was installed, then
# configures, builds and runs tests/consumer against it (find_package), asks pkg-config, and builds
# examples/ on their own against it.
# cmake -DBUILD_DIR=... -DWORK_DIR=... -DSOURCE_DIR=... -DEXAMPLES_DIR=... -DGENERATOR=... -DCXX=... [-DSANITIZE=ON] -P run.cmake
function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE err)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}\n${err}")
  endif()
  set(out "${out}" PARENT_SCOPE)
endfunction()

file(REMOVE_RECURSE ${WORK_DIR})
set(prefix ${WORK_DIR}/prefix)
run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})

# Only the public headers: include/sffd/*.h.
file(GLOB_RECURSE headers RELATIVE ${prefix}/include ${prefix}/include/*)
foreach(h IN LISTS headers)
  if(NOT h MATCHES "^sffd/[a-z0-9_]+\\.h$")
    message(FATAL_ERROR "installed include dir holds ${h}")
  endif()
endforeach()
foreach(f include/sffd/sffd.h lib/cmake/sffd/sffdConfig.cmake lib/cmake/sffd/sffdConfigVersion.cmake
          lib/pkgconfig/sffd.pc bin/sffd)
  if(NOT EXISTS ${prefix}/${f})
    message(FATAL_ERROR "not installed: ${f}")
  endif()
endforeach()
run(${prefix}/bin/sffd --help)   # the tool finds the installed library

# A sanitizer build of sffd (SFFD_SANITIZE) needs its runtime first in the application too.
set(flags "")
if(SANITIZE)
  set(flags -DCMAKE_CXX_FLAGS=-fsanitize=address,undefined -DCMAKE_EXE_LINKER_FLAGS=-fsanitize=address,undefined)
endif()
run(${CMAKE_COMMAND} -S ${SOURCE_DIR} -B ${WORK_DIR}/build -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX}
    -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release ${flags})
run(${CMAKE_COMMAND} --build ${WORK_DIR}/build)
run(${WORK_DIR}/build/app)
message(STATUS "consumer: ${out}")

set(ENV{PKG_CONFIG_PATH} ${prefix}/lib/pkgconfig)
run(pkg-config --cflags --libs sffd)
if(NOT out MATCHES "-I[^ ]*/include" OR NOT out MATCHES "-lsffd")
  message(FATAL_ERROR "pkg-config sffd gave: ${out}")
endif()

if(EXAMPLES_DIR)
  run(${CMAKE_COMMAND} -S ${EXAMPLES_DIR} -B ${WORK_DIR}/examples -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX}
      -DCMAKE_PREFIX_PATH=${prefix} -DCMAKE_BUILD_TYPE=Release ${flags})
  run(${CMAKE_COMMAND} --build ${WORK_DIR}/examples)
endif()
