// libFuzzer target: any bytes as a scenario file. The loader must never crash, leak or
// hit undefined behaviour, and must either return a scene or at least one error with a
// location, never both and never neither. A loaded scene must keep the bounds the loader
// promises (positive finite dt and duration). What the fuzzer finds is fixed and its
// input kept in validation/fuzz/regressions/, which a normal ctest replays.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "physval/validation/scenario_loader.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const physval::ScenarioLoad load = physval::parse_scenario(text, "fuzz.toml");
  if (load.scene.has_value() == !load.errors.empty()) std::abort();   // a scene xor errors
  for (const physval::Diagnostic& d : load.errors) {
    if (d.file != "fuzz.toml" || d.message.empty()) std::abort();
  }
  if (load.scene) {
    const physval::Scene& s = *load.scene;
    if (!(s.dt > 0.0) || !std::isfinite(s.dt) || !(s.duration > 0.0) || !std::isfinite(s.duration)) std::abort();
  }
  return 0;
}
