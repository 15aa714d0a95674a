# vista::OpenSceneGraph: FindOpenSceneGraph's result (variables only, no
# target) as one imported INTERFACE target, so that the exported link
# interfaces of vista::scene and vista::nodes name a target rather than this
# machine's library paths. Used by the build (CMakeLists.txt) and by the
# installed package (vistaConfig.cmake), each after
# find_package(OpenSceneGraph ...). Debug/optimized keyword pairs become
# generator expressions on the consumer's configuration.
if(NOT TARGET vista::OpenSceneGraph)
  set(_vista_osg_libs "")
  set(_vista_osg_keyword "")
  foreach(_vista_item IN LISTS OPENSCENEGRAPH_LIBRARIES)
    if(_vista_item STREQUAL "optimized" OR _vista_item STREQUAL "debug" OR _vista_item STREQUAL "general")
      set(_vista_osg_keyword "${_vista_item}")
    elseif(_vista_osg_keyword STREQUAL "optimized")
      list(APPEND _vista_osg_libs "$<$<NOT:$<CONFIG:Debug>>:${_vista_item}>")
      set(_vista_osg_keyword "")
    elseif(_vista_osg_keyword STREQUAL "debug")
      list(APPEND _vista_osg_libs "$<$<CONFIG:Debug>:${_vista_item}>")
      set(_vista_osg_keyword "")
    else()
      list(APPEND _vista_osg_libs "${_vista_item}")
      set(_vista_osg_keyword "")
    endif()
  endforeach()
  add_library(vista::OpenSceneGraph INTERFACE IMPORTED)
  set_target_properties(vista::OpenSceneGraph PROPERTIES
    INTERFACE_INCLUDE_DIRECTORIES "${OPENSCENEGRAPH_INCLUDE_DIRS}"
    INTERFACE_LINK_LIBRARIES "${_vista_osg_libs}")
  unset(_vista_osg_libs)
  unset(_vista_osg_keyword)
  unset(_vista_item)
endif()
