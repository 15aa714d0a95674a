# The ctest fixture SmallPagedCity (tests/common/small_paged_city.h): the small paged city
# generated once per test run for every test that reads it.
#   cmake -DMODE=setup -DVISTA=<vista> -DDIR=<folder> "-DARGS=<gen arguments>" -P paged_city_fixture.cmake
#   cmake -DMODE=cleanup -DDIR=<folder> -P paged_city_fixture.cmake
#   cmake -DMODE=selftest -DDIR=<scratch folder> -P paged_city_fixture.cmake
# setup: DIR afresh, `vista gen ARGS -q --threads 1 -o DIR/city.paged --stats DIR/stats.json`,
# then ARGS into DIR/args.txt (the tests check them) and the SHA-256 of every file under
# DIR/city.paged into DIR/city.sha256.
# cleanup: fails, naming each file added, removed or changed under DIR/city.paged since the
# setup (the tests read the city in place and copy it to change it), and removes DIR either way.
# selftest: plants a change, a removal and an addition in a scratch tree under DIR and fails
# unless the cleanup's comparison names exactly those (DIR is removed afterwards).
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

# The files under DIR/city.paged added, removed or changed since DIR/city.sha256 was written.
function(changed_files dir out)
  set(changed "")
  if(EXISTS "${dir}/city.sha256")
    file(READ "${dir}/city.sha256" before)
    hash_tree("${dir}/city.paged" after)
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
  set(${out} "${changed}" PARENT_SCOPE)
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
  changed_files("${DIR}" changed)
  if(EXISTS "${DIR}")
    file(CHMOD_RECURSE "${DIR}" DIRECTORY_PERMISSIONS OWNER_READ OWNER_WRITE OWNER_EXECUTE
         FILE_PERMISSIONS OWNER_READ OWNER_WRITE)
    file(REMOVE_RECURSE "${DIR}")
  endif()
  if(changed)
    list(JOIN changed ", " changed)
    message(FATAL_ERROR "paged_city_fixture: a test changed the shared city (copy it to change it): ${changed}")
  endif()
elseif(MODE STREQUAL "selftest")
  # A planted tree: unchanged it reports nothing; then one file changed, one removed and
  # one added, each named and nothing else.
  file(REMOVE_RECURSE "${DIR}")
  file(WRITE "${DIR}/city.paged/manifest.json" "{}")
  file(WRITE "${DIR}/city.paged/region_0_0.osgb" "a")
  file(WRITE "${DIR}/city.paged/records/region_0_0.json" "{}")
  file(WRITE "${DIR}/city.paged/records/region_1_0.json" "{}")
  hash_tree("${DIR}/city.paged" hashes)
  file(WRITE "${DIR}/city.sha256" "${hashes}")
  changed_files("${DIR}" unchanged)
  file(APPEND "${DIR}/city.paged/region_0_0.osgb" "b")
  file(REMOVE "${DIR}/city.paged/records/region_1_0.json")
  file(WRITE "${DIR}/city.paged/region_0_0.osgb.tmp" "")
  changed_files("${DIR}" changed)
  list(SORT changed)
  file(REMOVE_RECURSE "${DIR}")
  if(NOT unchanged STREQUAL "")
    message(FATAL_ERROR "paged_city_fixture: an unchanged tree reported changed: ${unchanged}")
  endif()
  if(NOT changed STREQUAL "records/region_1_0.json;region_0_0.osgb;region_0_0.osgb.tmp")
    message(FATAL_ERROR "paged_city_fixture: the planted changes were reported as '${changed}'")
  endif()
else()
  message(FATAL_ERROR "paged_city_fixture: MODE must be setup, cleanup or selftest, not '${MODE}'")
endif()
