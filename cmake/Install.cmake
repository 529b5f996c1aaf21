# Install rules: the library (component "library"), the public headers, the CMake package and the
# pkg-config file (component "development"), the sffd tool (component "tools"). Nothing else from
# the sources is installed: include/sffd/*.h only.
include(CMakePackageConfigHelpers)
set(SFFD_CMAKE_DIR ${CMAKE_INSTALL_LIBDIR}/cmake/sffd)

install(TARGETS sffd_lib EXPORT sffdTargets
  LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT library NAMELINK_COMPONENT development
  ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
  RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT library)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/include/sffd DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}
        COMPONENT development FILES_MATCHING PATTERN "*.h")
install(EXPORT sffdTargets NAMESPACE sffd:: DESTINATION ${SFFD_CMAKE_DIR} COMPONENT development)

# A static libsffd carries its private dependencies to the consumer's link: the config finds them.
get_target_property(SFFD_LIB_TYPE sffd_lib TYPE)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/sffdConfig.cmake.in
  ${PROJECT_BINARY_DIR}/sffdConfig.cmake INSTALL_DESTINATION ${SFFD_CMAKE_DIR})
write_basic_package_version_file(${PROJECT_BINARY_DIR}/sffdConfigVersion.cmake COMPATIBILITY SameMinorVersion)
install(FILES ${PROJECT_BINARY_DIR}/sffdConfig.cmake ${PROJECT_BINARY_DIR}/sffdConfigVersion.cmake
        DESTINATION ${SFFD_CMAKE_DIR} COMPONENT development)

if(SFFD_LIB_TYPE STREQUAL "STATIC_LIBRARY")
  set(SFFD_PC_PRIVATE_LIBS "-lOpenMeshCore -lglfw -ldl -pthread")
endif()
# Relocatable: the prefix is found from the .pc file's own place (cmake --install --prefix P).
file(RELATIVE_PATH SFFD_PC_UP /r/${CMAKE_INSTALL_LIBDIR}/pkgconfig /r)
string(REGEX REPLACE "/$" "" SFFD_PC_UP "${SFFD_PC_UP}")
configure_file(${PROJECT_SOURCE_DIR}/cmake/sffd.pc.in ${PROJECT_BINARY_DIR}/sffd.pc @ONLY)
install(FILES ${PROJECT_BINARY_DIR}/sffd.pc DESTINATION ${CMAKE_INSTALL_LIBDIR}/pkgconfig COMPONENT development)

if(TARGET sffd)
  install(TARGETS sffd RUNTIME DESTINATION ${CMAKE_INSTALL_BINDIR} COMPONENT tools)
endif()
