# vista_install_room(<target> <export-name> [EXCLUDE <subdir>...])
#
# Makes a room's library part of the C++ package (find_package(vista)):
# exported as vista::<export-name> in the export set vistaTargets, the
# archive installed to the library directory, and the room's headers (the
# *.h files of the folder that calls this, without the listed subfolders,
# which are other rooms or not part of any interface) installed under
# include/vista/<folder>, so that the include paths users write in the tree
# ("citygen/generate.h", "runtime/engine/ray_scene.h") stay the same against
# an installed vista (vista::options puts include/vista on their path).
function(vista_install_room target export_name)
  cmake_parse_arguments(R "" "" "EXCLUDE" ${ARGN})
  set_target_properties(${target} PROPERTIES EXPORT_NAME ${export_name})
  if(NOT VISTA_INSTALL_PACKAGE)
    return()
  endif()
  install(TARGETS ${target} EXPORT vistaTargets
    ARCHIVE DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development
    LIBRARY DESTINATION ${CMAKE_INSTALL_LIBDIR} COMPONENT development)
  file(RELATIVE_PATH folder ${PROJECT_SOURCE_DIR} ${CMAKE_CURRENT_SOURCE_DIR})
  set(excludes "")
  foreach(sub IN LISTS R_EXCLUDE)
    list(APPEND excludes PATTERN ${sub} EXCLUDE)
  endforeach()
  install(DIRECTORY ${CMAKE_CURRENT_SOURCE_DIR}/
    DESTINATION ${CMAKE_INSTALL_INCLUDEDIR}/vista/${folder}
    COMPONENT development
    FILES_MATCHING PATTERN "*.h" ${excludes})
endfunction()
