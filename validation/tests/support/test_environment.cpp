// Linked into every physval gtest executable (physval_add_tests): the environment ctest
// gives the tests (top-level CMakeLists.txt), also when an executable is run by hand from
// any folder, e.g. ./build/validation/physval_validation_tests --gtest_filter=...
//  - PHYSVAL_BUNDLED_PLUGIN_DIR=<build>/plugins unless set: the bundled engines (Chipmunk2D,
//    ODE) join the registry; without them every built-in scenario, which holds their
//    [gate.chipmunk] and [gate.ode] bounds, is refused ("unknown key"), since the
//    executables do not sit beside <build>/plugins as physval does.
//  - XDG_CACHE_HOME=<build>/test-cache: the reference cache in the build tree, never in
//    the user's.
#include <cstdlib>

namespace {

const bool kTestEnvironment = [] {
  ::setenv("PHYSVAL_BUNDLED_PLUGIN_DIR", PHYSVAL_TEST_BUNDLED_PLUGIN_DIR, 0);
  ::setenv("XDG_CACHE_HOME", PHYSVAL_TEST_CACHE_HOME, 1);
  return true;
}();

}  // namespace
