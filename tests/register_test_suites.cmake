# Registers one ctest test per googletest test suite of a test program (cmake -P, after each link).
#
# Why per suite and not per test (gtest_discover_tests): on lavapipe most of a rendering test's time
# is the driver compiling the engine's compute pipelines when the test's renderer is created (about
# 3 s, the tile-local sort's two variants 2.4 s of it), and a process per test paid that 763 times a
# run. A process per suite pays it once per suite and still runs the suites in parallel (ctest -j).
# The suite's output, shown on failure, names the failing tests; a suite that hangs is stopped at its
# TIMEOUT and its output ends at the test that hung ("[ RUN      ] Suite.Test").
#
# Variables: PROGRAM (the test program), OUTPUT (the file of add_test calls to write), TIMEOUT
# (seconds a suite may run), ENVIRONMENT (list of NAME=VALUE the suites run with).
foreach(required PROGRAM OUTPUT TIMEOUT)
  if(NOT DEFINED ${required})
    message(FATAL_ERROR "register_test_suites.cmake: ${required} is not set")
  endif()
endforeach()

execute_process(COMMAND "${PROGRAM}" --gtest_list_tests
                OUTPUT_VARIABLE listing ERROR_VARIABLE errors RESULT_VARIABLE status TIMEOUT 120)
if(NOT status EQUAL 0)
  file(REMOVE "${OUTPUT}")
  message(FATAL_ERROR "cannot list the tests of ${PROGRAM} (${status}):\n${listing}${errors}")
endif()

# --gtest_list_tests prints each suite at the start of a line ("Suite." or "Prefix/Suite.  # TypeParam
# = ..."), its tests indented below it.
string(REPLACE ";" "\\;" listing "${listing}")
string(REPLACE "\n" ";" lines "${listing}")
set(suites "")
foreach(line IN LISTS lines)
  if(line MATCHES "^([^ #][^ ]*)\\.")
    list(APPEND suites "${CMAKE_MATCH_1}")
  endif()
endforeach()
list(REMOVE_DUPLICATES suites)
if(NOT suites)
  file(REMOVE "${OUTPUT}")
  message(FATAL_ERROR "${PROGRAM} lists no test suites:\n${listing}")
endif()

set(text "# Written by tests/register_test_suites.cmake from ${PROGRAM} --gtest_list_tests\n")
foreach(suite IN LISTS suites)
  # The test's name is the suite's googletest filter, so that `ctest -R` and `--gtest_filter` read alike.
  string(APPEND text "add_test([==[${suite}.*]==] [==[${PROGRAM}]==] [==[--gtest_filter=${suite}.*]==])\n")
  string(APPEND text "set_tests_properties([==[${suite}.*]==] PROPERTIES TIMEOUT ${TIMEOUT}"
                     " SKIP_REGULAR_EXPRESSION [==[\\[  SKIPPED \\]]==]"
                     " ENVIRONMENT [==[${ENVIRONMENT}]==])\n")
endforeach()
file(WRITE "${OUTPUT}" "${text}")
list(LENGTH suites count)
message(STATUS "${PROGRAM}: ${count} test suites registered with ctest")
