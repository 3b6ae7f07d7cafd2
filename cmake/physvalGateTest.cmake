# physval_add_gate_test(NAME name PLUGIN target SCENARIOS path...
#                       [ENGINES engine...] [TIMEOUT seconds] [ARGS arg...])
#
# Adds a ctest `name` that runs
#   physval gate <SCENARIOS> --plugin $<TARGET_FILE:PLUGIN> [--engines ENGINES] --timeout T
#                --out <build>/<name> --junit <build>/<name>/junit.xml --cache <build>/physval-cache
# and passes when physval exits 0: every run of the plugin ran, every [gate] limit,
# [gate.<plugin>] bound and expectation held. PLUGIN is a CMake target (a MODULE or SHARED
# library) or a path to one. ENGINES restricts the engines run (typically the plugin's own
# name; physval's reference engine runs regardless, for the divergence metrics). TIMEOUT
# (default 120) stops a run that hangs: it is then reported as an error. ARGS are passed on
# to `physval gate` (e.g. --baseline results.json, -j 2).
function(physval_add_gate_test)
  cmake_parse_arguments(PARSE_ARGV 0 arg "" "NAME;PLUGIN;TIMEOUT" "SCENARIOS;ENGINES;ARGS")
  if(NOT arg_NAME OR NOT arg_PLUGIN OR NOT arg_SCENARIOS)
    message(FATAL_ERROR "physval_add_gate_test: NAME, PLUGIN and SCENARIOS are required")
  endif()
  if(arg_UNPARSED_ARGUMENTS)
    message(FATAL_ERROR "physval_add_gate_test: unknown arguments: ${arg_UNPARSED_ARGUMENTS}")
  endif()
  if(NOT arg_TIMEOUT)
    set(arg_TIMEOUT 120)
  endif()
  if(TARGET ${arg_PLUGIN})
    set(plugin "$<TARGET_FILE:${arg_PLUGIN}>")
  else()
    get_filename_component(plugin "${arg_PLUGIN}" ABSOLUTE)
  endif()
  set(scenarios "")
  foreach(s IN LISTS arg_SCENARIOS)
    get_filename_component(s "${s}" ABSOLUTE)
    list(APPEND scenarios "${s}")
  endforeach()
  set(engines "")
  if(arg_ENGINES)
    list(JOIN arg_ENGINES "," joined)
    set(engines --engines "${joined}")
  endif()
  set(out "${CMAKE_CURRENT_BINARY_DIR}/${arg_NAME}")
  add_test(NAME ${arg_NAME}
           COMMAND physval::physval gate ${scenarios} --plugin "${plugin}" ${engines} --timeout ${arg_TIMEOUT}
                   --out "${out}" --junit "${out}/junit.xml" --cache "${CMAKE_CURRENT_BINARY_DIR}/physval-cache"
                   ${arg_ARGS})
endfunction()
