# The C++ package: find_package(vista CONFIG) after `cmake --install`.
#
# Exports the rooms' libraries (static; vista_install_room in each room's
# CMakeLists.txt) as vista::foundation, vista::citygen, vista::scene,
# vista::traffic, vista::engine, vista::nodes, vista::render, vista::bake, with vista::options
# (C++17, GLM definitions, the include directory include/vista). The static
# archives carry their private dependencies as link-only entries, so the
# config finds every package that the archives need at link time, not only
# those their headers need (vistaConfig.cmake.in).
include(CMakePackageConfigHelpers)

set(VISTA_INSTALL_CMAKEDIR ${CMAKE_INSTALL_LIBDIR}/cmake/vista CACHE STRING
  "Where the CMake package files go (relative to the install prefix)")
mark_as_advanced(VISTA_INSTALL_CMAKEDIR)

install(TARGETS vista_options EXPORT vistaTargets)
install(EXPORT vistaTargets
  NAMESPACE vista::
  FILE vistaTargets.cmake
  DESTINATION ${VISTA_INSTALL_CMAKEDIR}
  COMPONENT development)

string(REPLACE ";" " " VISTA_OSG_COMPONENT_ARGS "${VISTA_OSG_COMPONENTS}")  # for vistaConfig.cmake.in
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/vistaConfig.cmake.in
  ${PROJECT_BINARY_DIR}/vistaConfig.cmake
  INSTALL_DESTINATION ${VISTA_INSTALL_CMAKEDIR})
# 0.x: a minor version may change the interfaces, so only the same minor
# version satisfies a request.
write_basic_package_version_file(${PROJECT_BINARY_DIR}/vistaConfigVersion.cmake
  VERSION ${PROJECT_VERSION}
  COMPATIBILITY SameMinorVersion)
install(FILES
    ${PROJECT_BINARY_DIR}/vistaConfig.cmake
    ${PROJECT_BINARY_DIR}/vistaConfigVersion.cmake
    ${PROJECT_SOURCE_DIR}/cmake/vistaOpenSceneGraph.cmake
  DESTINATION ${VISTA_INSTALL_CMAKEDIR}
  COMPONENT development)
