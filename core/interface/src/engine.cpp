#include "physval/engine/engine.hpp"

#include <algorithm>

namespace physval {

std::vector<std::string> unsupported_features(const EngineInfo& info, const Scene& scene) {
  std::vector<std::string> missing;
  for (Feature f : scene_features(scene)) {
    if (std::find(info.features.begin(), info.features.end(), f) == info.features.end()) {
      missing.emplace_back(feature_name(f));
    }
  }
  return missing;
}

}  // namespace physval
