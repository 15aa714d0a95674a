# The Debian package: `cpack -G DEB` in the build directory writes
# vista_<version>_<arch>.deb with everything `cmake --install` installs, under
# /usr: the `vista` tool, the osgDB plugin (lib/osgPlugins-<osg version>/,
# where OSG looks for plugins), and the C++ package (static libraries,
# headers under include/vista, lib/cmake/vista), and the Python module
# `vista` under lib/python3/dist-packages when pybind11 was found.
#
# Depends: the shared libraries the tool and the plugin load (found by
# dpkg-shlibdeps), and the -dev packages whose CMake packages, headers and
# libraries find_package(vista) and the static archives need at a consumer's
# build (vistaConfig.cmake.in), when the C++ package is installed.
set(CPACK_PACKAGE_NAME vista)
set(CPACK_PACKAGE_VERSION ${PROJECT_VERSION})
set(CPACK_PACKAGE_VENDOR "vista")
set(CPACK_PACKAGE_DESCRIPTION_SUMMARY
  "Procedural city generator and OpenSceneGraph walkthrough runtime (tool, osgDB plugin, C++ libraries)")
set(CPACK_PACKAGE_DESCRIPTION
  "vista generates synthetic cities (street graphs, buildings, trees) and walks through them fast, \
drawing the near field with OpenSceneGraph and ray casting the far field with Embree. \
This package holds the vista command, the osgDB plugin that lets stock OSG tools read vista scene files, \
and the C++ libraries with their headers and CMake package (find_package(vista)).")
set(CPACK_PACKAGE_CONTACT "vista maintainers" CACHE STRING "Maintainer field of the Debian package")
set(CPACK_PACKAGING_INSTALL_PREFIX /usr)
set(CPACK_GENERATOR DEB)
set(CPACK_DEBIAN_FILE_NAME DEB-DEFAULT)
set(CPACK_DEBIAN_PACKAGE_SECTION graphics)
set(CPACK_DEBIAN_PACKAGE_SHLIBDEPS ON)
if(VISTA_INSTALL_PACKAGE)
  set(CPACK_DEBIAN_PACKAGE_DEPENDS
    "libopenscenegraph-dev, libembree-dev, libtbb-dev, libcgal-dev, libgmp-dev, libmpfr-dev, libglm-dev, \
nlohmann-json3-dev, libpng-dev, zlib1g-dev, libbz2-dev, libexpat1-dev, libgl-dev, libopengl-dev")
  set(CPACK_DEBIAN_PACKAGE_SUGGESTS "cmake (>= 3.20)")
endif()
# The Python module (cmd/python, when built) is compiled against this Python's ABI and returns numpy arrays.
get_property(_vista_py GLOBAL PROPERTY VISTA_PYTHON_VERSION)
if(TARGET vista_python AND _vista_py)
  if(CPACK_DEBIAN_PACKAGE_DEPENDS)
    string(APPEND CPACK_DEBIAN_PACKAGE_DEPENDS ", ")
  endif()
  string(APPEND CPACK_DEBIAN_PACKAGE_DEPENDS
    "python3 (>= ${_vista_py}), python3 (<< ${_vista_py}.99), python3-numpy")
  if(CPACK_DEBIAN_PACKAGE_SUGGESTS)
    string(APPEND CPACK_DEBIAN_PACKAGE_SUGGESTS ", ")
  endif()
  string(APPEND CPACK_DEBIAN_PACKAGE_SUGGESTS "python3-torch")
endif()
include(CPack)
