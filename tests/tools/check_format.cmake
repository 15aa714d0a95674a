# Fails, listing the files, when clang-format would change any C++ file of the
# project (the rooms, the commands, the tests and the examples).
file(GLOB_RECURSE _files RELATIVE "${ROOT}"
  "${ROOT}/foundation/*.[ch]*" "${ROOT}/citygen/*.[ch]*" "${ROOT}/runtime/*.[ch]*"
  "${ROOT}/nodes/*.[ch]*" "${ROOT}/bake/*.[ch]*" "${ROOT}/cmd/*.[ch]*"
  "${ROOT}/tests/*.[ch]*" "${ROOT}/examples/*.[ch]*")
list(FILTER _files INCLUDE REGEX "\\.(h|cpp)$")
list(LENGTH _files _n)
# One clang-format run over every file; its diagnostics name each file it would change.
execute_process(COMMAND "${CLANG_FORMAT}" --style=file --dry-run -Werror ${_files}
  WORKING_DIRECTORY "${ROOT}" RESULT_VARIABLE _rc OUTPUT_QUIET ERROR_VARIABLE _err)
if(NOT _rc EQUAL 0)
  string(REGEX MATCHALL "[^ \n:]+\\.(h|cpp):[0-9]+:[0-9]+: error" _hits "${_err}")
  set(_bad "")
  foreach(_h IN LISTS _hits)
    string(REGEX REPLACE ":[0-9]+:[0-9]+: error$" "" _f "${_h}")
    list(APPEND _bad "${_f}")
  endforeach()
  list(REMOVE_DUPLICATES _bad)
  list(JOIN _bad "\n  " _list)
  message(FATAL_ERROR "clang-format would change these files (clang-format -i FILE):\n  ${_list}")
endif()
message(STATUS "${_n} C++ files formatted as .clang-format says")
