// The reference cache: a converged reference is deterministic, so it is stored under a
// hash of everything it depends on (the scenario file's text, the step, duration and
// sampling it runs with, the reference engine and its options, the physval version and
// the physval executable itself) and read back instead of recomputed.
#pragma once

#include <filesystem>
#include <string>

#include "physval/validation/comparator.hpp"

namespace physval {

// $XDG_CACHE_HOME/physval/references, else ~/.cache/physval/references.
std::filesystem::path default_reference_cache_dir();

// What the cached reference depends on, as text (stored in the entry and compared on
// reading, so a hash collision can never return another scene's reference). Empty
// when the scene was not loaded from a file (nothing to key it on: not cached).
std::string reference_cache_key(const Scene& scene, const RunOptions& options);

struct CachedReference {
  Reference reference;
  bool from_cache = false;
};

// The reference for `scene` (already effective) from options.reference_cache when an
// entry with the same key is there, else make_reference(), stored there when it is
// available. Entries are written to a temporary file and renamed into place, so a
// concurrent reader sees a whole entry or none, and concurrent writers of one key
// write the same bytes. An unreadable entry counts as missing.
CachedReference cached_reference(const Scene& scene, const RunOptions& options);

}  // namespace physval
