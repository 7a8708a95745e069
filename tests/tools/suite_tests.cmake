# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# Read by CTest (a TEST_INCLUDE_FILES script, tests/CMakeLists.txt) in the sanitized build: registers one
# CTest test per GoogleTest suite of lumx_tests instead of one per test. A sanitized process takes about
# 0.28 s to start and to check for leaks at exit, so the ~580 tests cost about 160 s of start-ups alone;
# their 131 suites under a quarter of that.
#
# The test list comes from the program itself (--gtest_list_tests), each time CTest runs, so the groups
# hold exactly the program's tests. Tests whose full name matches the CMake regular expression in the
# environment variable LUMX_TESTS_LEFT_OUT are not run (scripts/test.sh --sanitize sets it).
#
# Set by the including file: LUMX_TESTS (the program), LUMX_TESTS_DIR (working directory), LUMX_TESTS_TIMEOUT.

execute_process(COMMAND "${LUMX_TESTS}" --gtest_list_tests
                WORKING_DIRECTORY "${LUMX_TESTS_DIR}" OUTPUT_VARIABLE listing RESULT_VARIABLE status TIMEOUT 120)
if(NOT status EQUAL 0)
  # Makes the failure a failing test with the program's own message, rather than an empty suite.
  add_test(lumx_tests.list "${LUMX_TESTS}" --gtest_list_tests)
  return()
endif()

# The listing: "Suite." lines (instantiated suites "Prefix/Suite."), then "  Test" lines; parameterised
# suites and tests carry a "  # TypeParam = …" or "  # GetParam() = …" comment, removed first because
# its text may hold ';' or brackets, which would break the list.
string(REGEX REPLACE "  #[^\n]*" "" listing "${listing}")
string(REPLACE ";" "" listing "${listing}")
string(REPLACE "\n" ";" lines "${listing}")
set(left_out "$ENV{LUMX_TESTS_LEFT_OUT}")
set(suites 0)  # suite i (1..suites): its name suite_<i> and remaining tests tests_<i>
foreach(line IN LISTS lines)
  if(line MATCHES "^([^ ]+)\\.$")
    math(EXPR suites "${suites} + 1")
    set(suite_${suites} "${CMAKE_MATCH_1}")
    set(tests_${suites} "")
  elseif(line MATCHES "^  ([^ ]+)$" AND suites GREATER 0)
    set(name "${suite_${suites}}.${CMAKE_MATCH_1}")
    if(NOT left_out STREQUAL "" AND name MATCHES "${left_out}")
      continue()
    endif()
    list(APPEND tests_${suites} "${name}")
  endif()
endforeach()

# One test per suite with tests left, in the program's order, running exactly those tests by name.
if(suites EQUAL 0)
  return()
endif()
foreach(i RANGE 1 ${suites})
  if(tests_${i} STREQUAL "")
    continue()
  endif()
  list(JOIN tests_${i} ":" filter)
  add_test("${suite_${i}}" "${LUMX_TESTS}" "--gtest_filter=${filter}")
  set_tests_properties("${suite_${i}}" PROPERTIES WORKING_DIRECTORY "${LUMX_TESTS_DIR}" TIMEOUT "${LUMX_TESTS_TIMEOUT}")
endforeach()
