// libphysval_chipmunk.so: the Chipmunk2D adapter as a physval engine plugin (plugin ABI v1).
// `physval run --plugin path/to/libphysval_chipmunk.so` in a physval built without it.
#include "engine_plugin_bridge.hpp"
#include "physval/adapters/chipmunk_adapter.hpp"

namespace {
struct ChipmunkTraits {
  static physval::EngineFactory factory() { return physval::chipmunk_engine_factory(); }
};
using ChipmunkPlugin = physval::plugin_bridge::BridgedEngine<ChipmunkTraits>;
}  // namespace

PHYSVAL_PLUGIN_DEFINE(ChipmunkPlugin)
