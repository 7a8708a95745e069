# SPDX-License-Identifier: Apache-2.0
# Copyright Contributors to the lumx project.
# Read by CTest (a TEST_INCLUDE_FILES script, tests/CMakeLists.txt) in the sanitized build: registers one
# CTest test per GoogleTest suite and tier of lumx_tests instead of one per test, because a sanitized
# process's start-up and leak check at exit would otherwise cost more than most tests. Each CTest test
# carries its tier as its label (tests/tiers.cmake), so the sanitized stage selects by label.
#
# The test lists come from the program itself (--gtest_list_tests with each tier's filter), each time CTest
# runs, so the groups hold exactly the program's tests.
#
# Set by the including file: LUMX_TESTS (the program), LUMX_TESTS_DIR (working directory), LUMX_TESTS_TIMEOUT,
# LUMX_TIERS and, for each tier T, LUMX_TIER_FILTER_T (a GoogleTest filter; the tiers are disjoint).

set(registered "")  # the CTest names given so far
foreach(tier IN LISTS LUMX_TIERS)
  execute_process(COMMAND "${LUMX_TESTS}" --gtest_list_tests "--gtest_filter=${LUMX_TIER_FILTER_${tier}}"
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
  set(suites 0)  # suite i (1..suites): its name suite_<i> and tests tests_<i>
  foreach(line IN LISTS lines)
    if(line MATCHES "^([^ ]+)\\.$")
      math(EXPR suites "${suites} + 1")
      set(suite_${suites} "${CMAKE_MATCH_1}")
      set(tests_${suites} "")
    elseif(line MATCHES "^  ([^ ]+)$" AND suites GREATER 0)
      list(APPEND tests_${suites} "${suite_${suites}}.${CMAKE_MATCH_1}")
    endif()
  endforeach()

  # One test per suite with tests in this tier, in the program's order, running exactly those tests by
  # name; a suite whose tests span tiers is named "Suite[tier]" in all but its first.
  if(suites EQUAL 0)
    continue()
  endif()
  foreach(i RANGE 1 ${suites})
    if(tests_${i} STREQUAL "")
      continue()
    endif()
    set(name "${suite_${i}}")
    list(FIND registered "${name}" seen)  # (a CTest script has no policies set: no IN_LIST)
    if(NOT seen EQUAL -1)
      set(name "${suite_${i}}[${tier}]")
    endif()
    list(APPEND registered "${name}")
    list(JOIN tests_${i} ":" filter)
    add_test("${name}" "${LUMX_TESTS}" "--gtest_filter=${filter}")
    set_tests_properties("${name}" PROPERTIES WORKING_DIRECTORY "${LUMX_TESTS_DIR}" TIMEOUT "${LUMX_TESTS_TIMEOUT}"
                         LABELS "${tier}")
  endforeach()
endforeach()
