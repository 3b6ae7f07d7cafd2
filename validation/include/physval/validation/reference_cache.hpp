// The reference cache: a converged reference is deterministic, so it is stored under a
// hash of everything it depends on (the scenario file's text, the step, duration and
// sampling it runs with, the reference engine and its options, the physval version and
// the physval executable itself) and read back instead of recomputed.
#pragma once

#include <filesystem>
#include <string>
#include <string_view>

#include "physval/validation/comparator.hpp"

namespace physval {

// A 128-bit hash of bytes (hex, 32 digits): cache entries' seals, file identities.
std::string hash_file_bytes(std::string_view bytes);

// The hash of the running physval executable's bytes (computed once): any rebuild with
// other code has another, even at the same version number.
const std::string& executable_hash();

// The loader notes the text of each scenario file as it read it. The cache key holds the
// file's text as it is when the reference is keyed; when that is no longer the text the
// scene was parsed from (the file was edited during the run), the reference is computed
// from the scene as loaded and neither read from nor stored in the cache: stored under
// the edited text, it would be served later as the edited scene's reference.
void note_loaded_scenario_text(const std::string& file, const std::string& text);

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
