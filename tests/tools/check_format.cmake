# Fails, listing the files, when clang-format would change any C++ file of the
# project (the rooms, the commands, the tests and the examples).
file(GLOB_RECURSE _files RELATIVE "${ROOT}"
  "${ROOT}/foundation/*.[ch]*" "${ROOT}/citygen/*.[ch]*" "${ROOT}/runtime/*.[ch]*"
  "${ROOT}/nodes/*.[ch]*" "${ROOT}/bake/*.[ch]*" "${ROOT}/cmd/*.[ch]*"
  "${ROOT}/tests/*.[ch]*" "${ROOT}/examples/*.[ch]*")
list(FILTER _files INCLUDE REGEX "\\.(h|cpp)$")
set(_bad "")
foreach(_f IN LISTS _files)
  execute_process(COMMAND "${CLANG_FORMAT}" --style=file --dry-run -Werror "${_f}"
    WORKING_DIRECTORY "${ROOT}" RESULT_VARIABLE _rc OUTPUT_QUIET ERROR_QUIET)
  if(NOT _rc EQUAL 0)
    list(APPEND _bad "${_f}")
  endif()
endforeach()
list(LENGTH _files _n)
if(_bad)
  list(JOIN _bad "\n  " _list)
  message(FATAL_ERROR "clang-format would change these files (clang-format -i FILE):\n  ${_list}")
endif()
message(STATUS "${_n} C++ files formatted as .clang-format says")
