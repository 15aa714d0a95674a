# The ctest fixture SmallPagedCity (tests/common/small_paged_city.h): the small paged city
# generated once per test run for every test that reads it.
#   cmake -DMODE=setup -DVISTA=<vista> -DDIR=<folder> "-DARGS=<gen arguments>" -P paged_city_fixture.cmake
#   cmake -DMODE=cleanup -DDIR=<folder> -P paged_city_fixture.cmake
# setup: DIR afresh, `vista gen ARGS -q --threads 1 -o DIR/city.paged --stats DIR/stats.json`,
# then ARGS into DIR/args.txt (the tests check them) and the SHA-256 of every file under
# DIR/city.paged into DIR/city.sha256.
# cleanup: fails, naming each file added, removed or changed under DIR/city.paged since the
# setup (the tests read the city in place and copy it to change it), and removes DIR either way.
cmake_minimum_required(VERSION 3.20)

function(hash_tree root out)
  file(GLOB_RECURSE files LIST_DIRECTORIES false RELATIVE "${root}" "${root}/*")
  list(SORT files)
  set(lines "")
  foreach(f IN LISTS files)
    file(SHA256 "${root}/${f}" h)
    string(APPEND lines "${h}  ${f}\n")
  endforeach()
  set(${out} "${lines}" PARENT_SCOPE)
endfunction()

if(NOT DIR)
  message(FATAL_ERROR "paged_city_fixture: DIR is not set")
endif()
if(MODE STREQUAL "setup")
  file(REMOVE_RECURSE "${DIR}")
  file(MAKE_DIRECTORY "${DIR}")
  separate_arguments(gen_args UNIX_COMMAND "${ARGS}")
  execute_process(
    COMMAND "${VISTA}" gen ${gen_args} -q --threads 1 -o "${DIR}/city.paged" --stats "${DIR}/stats.json"
    RESULT_VARIABLE rc)
  if(NOT rc EQUAL 0)
    file(REMOVE_RECURSE "${DIR}")
    message(FATAL_ERROR "paged_city_fixture: vista gen ${ARGS} failed (${rc})")
  endif()
  file(WRITE "${DIR}/args.txt" "${ARGS}")
  hash_tree("${DIR}/city.paged" hashes)
  file(WRITE "${DIR}/city.sha256" "${hashes}")
elseif(MODE STREQUAL "cleanup")
  set(changed "")
  if(EXISTS "${DIR}/city.sha256")
    file(READ "${DIR}/city.sha256" before)
    hash_tree("${DIR}/city.paged" after)
    string(REPLACE "\n" ";" lb "${before}")
    string(REPLACE "\n" ";" la "${after}")
    set(gone ${lb})
    set(came ${la})
    if(la)
      list(REMOVE_ITEM gone ${la})
    endif()
    if(lb)
      list(REMOVE_ITEM came ${lb})
    endif()
    foreach(line IN LISTS gone came)
      string(REGEX REPLACE "^[0-9a-f]+  " "" name "${line}")
      list(APPEND changed "${name}")
    endforeach()
    list(REMOVE_DUPLICATES changed)
  endif()
  if(EXISTS "${DIR}")
    file(CHMOD_RECURSE "${DIR}" DIRECTORY_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE
         FILE_PERMISSIONS OWNER_READ OWNER_WRITE)
    file(REMOVE_RECURSE "${DIR}")
  endif()
  if(changed)
    list(JOIN changed ", " changed)
    message(FATAL_ERROR "paged_city_fixture: a test changed the shared city (copy it to change it): ${changed}")
  endif()
else()
  message(FATAL_ERROR "paged_city_fixture: MODE must be setup or cleanup, not '${MODE}'")
endif()
