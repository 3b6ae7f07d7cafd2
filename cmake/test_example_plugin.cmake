# The out-of-tree test of the installed package (ctest physval_example_plugin_out_of_tree):
# install physval to a temporary prefix, configure examples/plugin against it, build the
# discs plugin, and run its gate test (physval_add_gate_test). Then check that the same
# function fails when discs misses a bound: a gate test that cannot fail proves nothing.
# Run as: cmake -DBUILD_DIR=... -DSOURCE_DIR=... -DWORK=... -DGENERATOR=... -DCXX=... -P this
foreach(v BUILD_DIR SOURCE_DIR WORK GENERATOR CXX)
  if(NOT DEFINED ${v})
    message(FATAL_ERROR "test_example_plugin.cmake: -D${v}= is required")
  endif()
endforeach()
file(REMOVE_RECURSE ${WORK})
set(prefix ${WORK}/prefix)

function(run)
  execute_process(COMMAND ${ARGN} RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
  if(NOT rc EQUAL 0)
    message(FATAL_ERROR "failed (${rc}): ${ARGN}\n${out}")
  endif()
endfunction()

run(${CMAKE_COMMAND} --install ${BUILD_DIR} --prefix ${prefix})
run(${CMAKE_COMMAND} -S ${SOURCE_DIR}/examples/plugin -B ${WORK}/discs -G ${GENERATOR} -DCMAKE_CXX_COMPILER=${CXX}
    -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH=${prefix})
run(${CMAKE_COMMAND} --build ${WORK}/discs)
run(${CMAKE_CTEST_COMMAND} --test-dir ${WORK}/discs --output-on-failure)
file(READ ${WORK}/discs/discs_gate/junit.xml junit)
if(NOT junit MATCHES "tests=\"3\"" OR NOT junit MATCHES "failures=\"0\"")
  message(FATAL_ERROR "discs_gate's JUnit does not hold 3 passing runs:\n${junit}")
endif()

# The failing direction: one bound of discs tightened below what it achieves.
file(COPY ${SOURCE_DIR}/examples/plugin/scenarios/head_on_elastic.toml DESTINATION ${WORK}/tight)
file(READ ${WORK}/tight/head_on_elastic.toml text)
string(REGEX REPLACE "\n\\[gate\\.discs\\]\n" "\n[gate.discs]\ncontact_time_error = 1e-6\n" tightened "${text}")
string(REGEX REPLACE "\ncontact_time_error = 1\\.6e-3" "" tightened "${tightened}")
if(tightened STREQUAL text)
  message(FATAL_ERROR "could not tighten head_on_elastic's [gate.discs]")
endif()
file(WRITE ${WORK}/tight/head_on_elastic.toml "${tightened}")
file(MAKE_DIRECTORY ${WORK}/tight-project)
file(WRITE ${WORK}/tight-project/CMakeLists.txt "
cmake_minimum_required(VERSION 3.25)
project(tight NONE)
find_package(physval CONFIG REQUIRED)
enable_testing()
physval_add_gate_test(NAME tight_gate PLUGIN ${WORK}/discs/libdiscs.so ENGINES discs SCENARIOS ${WORK}/tight)
")
run(${CMAKE_COMMAND} -S ${WORK}/tight-project -B ${WORK}/tight-build -G ${GENERATOR} -DCMAKE_PREFIX_PATH=${prefix})
execute_process(COMMAND ${CMAKE_CTEST_COMMAND} --test-dir ${WORK}/tight-build --output-on-failure
                RESULT_VARIABLE rc OUTPUT_VARIABLE out ERROR_VARIABLE out)
if(rc EQUAL 0 OR NOT out MATCHES "contact_time_error")
  message(FATAL_ERROR "a gate test with a bound discs misses passed (or failed for another reason):\n${out}")
endif()
message(STATUS "installed package: discs built out of tree, gated green; a tightened bound fails")
