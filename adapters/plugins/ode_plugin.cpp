// libphysval_ode.so: the ODE adapter as a physval engine plugin (plugin ABI v1).
// `physval run --plugin path/to/libphysval_ode.so` in a physval built without it.
#include "engine_plugin_bridge.hpp"
#include "physval/adapters/ode_adapter.hpp"

namespace {
struct OdeTraits {
  static physval::EngineFactory factory() { return physval::ode_engine_factory(); }
};
using OdePlugin = physval::plugin_bridge::BridgedEngine<OdeTraits>;
}  // namespace

PHYSVAL_PLUGIN_DEFINE(OdePlugin)
