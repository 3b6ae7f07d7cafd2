#include "physval/validation/reference_cache.hpp"

#include <unistd.h>

#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <iterator>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string_view>
#include <thread>

#include "physval/adapters/registry.hpp"
#include "physval/validation/run_record_io.hpp"

namespace physval {

namespace {

using nlohmann::json;

std::string read_bytes(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) return {};
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Two independent 64-bit FNV-1a hashes (different offset bases): the entry's file name.
std::string hash_hex(const std::string& text) {
  std::uint64_t h1 = 14695981039346656037ull, h2 = 0x9e3779b97f4a7c15ull;
  for (const char c : text) {
    const auto b = static_cast<std::uint8_t>(c);
    h1 = (h1 ^ b) * 1099511628211ull;
    h2 = (h2 ^ b) * 0x100000001b3ull + 0x632be59bd9b4e019ull;
  }
  char buf[40];
  std::snprintf(buf, sizeof buf, "%016llx%016llx", static_cast<unsigned long long>(h1),
                static_cast<unsigned long long>(h2));
  return buf;
}

std::string exact(double v) {
  char buf[40];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

json reference_to_json(const std::string& key, const Reference& ref) {
  json j;
  j["key"] = key;
  j["available"] = ref.available;
  j["converged"] = ref.converged;
  j["reason"] = ref.reason;
  j["dt"] = ref.dt;
  j["convergence_error"] = ref.convergence_error;
  j["seconds"] = ref.seconds;
  j["run"] = ref.run ? json::binary(encode_run_record(*ref.run)) : json(nullptr);
  return j;
}

// An entry's bytes: the CBOR document, then a newline and the hash of the document's
// bytes (32 hex digits). A flipped byte anywhere (a damaged disk, a file edited or
// overwritten in part) fails the hash, and the entry is recomputed: without it, a byte
// changed inside the run's series still decoded, and the run was compared with another
// reference than the one computed.
constexpr std::size_t kSealSize = 1 + 32;

std::string seal_of(const std::vector<std::uint8_t>& cbor) {
  return '\n' + hash_file_bytes(std::string_view(reinterpret_cast<const char*>(cbor.data()), cbor.size()));
}

std::optional<Reference> reference_from(const std::string& entry, const std::string& key) {
  if (entry.size() <= kSealSize || entry[entry.size() - kSealSize] != '\n') return std::nullopt;
  const std::string_view bytes(entry.data(), entry.size() - kSealSize);
  if (hash_file_bytes(bytes) != std::string_view(entry).substr(entry.size() - kSealSize + 1)) return std::nullopt;
  try {
    const json j = json::from_cbor(bytes.begin(), bytes.end());
    if (j.at("key").get<std::string>() != key) return std::nullopt;
    Reference ref;
    ref.available = j.at("available").get<bool>();
    ref.converged = j.at("converged").get<bool>();
    ref.reason = j.at("reason").get<std::string>();
    ref.dt = j.at("dt").get<double>();
    ref.convergence_error = j.at("convergence_error").get<double>();
    ref.seconds = j.at("seconds").get<double>();
    if (!j.at("run").is_null()) ref.run = decode_run_record(j.at("run").get_binary());
    return ref;
  } catch (const std::exception&) {
    return std::nullopt;
  }
}

void store(const std::filesystem::path& dir, const std::string& name, const std::string& key, const Reference& ref) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) return;
  static std::atomic<unsigned> counter{0};
  std::ostringstream tmp_name;
  tmp_name << ".tmp-" << ::getpid() << '-' << std::hash<std::thread::id>{}(std::this_thread::get_id()) << '-'
           << counter.fetch_add(1) << '-' << name;
  const std::filesystem::path tmp = dir / tmp_name.str();
  const std::vector<std::uint8_t> bytes = json::to_cbor(reference_to_json(key, ref));
  const std::string seal = seal_of(bytes);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) return;
    out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
    out.write(seal.data(), static_cast<std::streamsize>(seal.size()));
    out.flush();
    if (!out) {
      out.close();
      std::filesystem::remove(tmp, ec);
      return;
    }
  }
  std::filesystem::rename(tmp, dir / name, ec);   // atomic on one file system
  if (ec) std::filesystem::remove(tmp, ec);
}

}  // namespace

// Eight bytes at a time (two multiply-xorshift lanes): the executable is megabytes, and
// byte-wise FNV under the sanitizers' instrumentation took ~25 s per physval process.
#if defined(__clang__) || defined(__GNUC__)
__attribute__((no_sanitize("address", "undefined")))
#endif
std::string hash_file_bytes(std::string_view bytes) {
  std::uint64_t h1 = 14695981039346656037ull ^ bytes.size(), h2 = 0x9e3779b97f4a7c15ull;
  const std::size_t words = bytes.size() / 8;
  for (std::size_t i = 0; i < words; ++i) {
    std::uint64_t w;
    std::memcpy(&w, bytes.data() + 8 * i, 8);
    h1 = (h1 ^ w) * 0xff51afd7ed558ccdull;
    h1 ^= h1 >> 32;
    h2 = (h2 ^ w) * 0xc4ceb9fe1a85ec53ull + 0x632be59bd9b4e019ull;
    h2 ^= h2 >> 29;
  }
  return hash_hex(std::string(bytes.substr(8 * words)) + std::to_string(h1) + ":" + std::to_string(h2));
}

// The running executable's bytes, hashed once: any rebuild of physval with other code
// is another key, even at the same version number.
const std::string& executable_hash() {
  static const std::string hash = [] {
    std::ifstream in("/proc/self/exe", std::ios::binary | std::ios::ate);
    if (!in) return std::string("unknown-executable");
    const std::streamsize size = in.tellg();
    std::string bytes(static_cast<std::size_t>(std::max<std::streamsize>(size, 0)), '\0');
    in.seekg(0);
    if (size <= 0 || !in.read(bytes.data(), size)) return std::string("unknown-executable");
    return hash_file_bytes(bytes);
  }();
  return hash;
}

namespace {
std::mutex g_loaded_mutex;
std::map<std::string, std::string> g_loaded_text_hash;   // scenario file -> hash of the text parsed
}  // namespace

void note_loaded_scenario_text(const std::string& file, const std::string& text) {
  const std::string hash = hash_file_bytes(text);
  const std::lock_guard<std::mutex> lock(g_loaded_mutex);
  g_loaded_text_hash[file] = hash;
}

std::filesystem::path default_reference_cache_dir() {
  if (const char* xdg = std::getenv("XDG_CACHE_HOME"); xdg != nullptr && *xdg == '/') {
    return std::filesystem::path(xdg) / "physval" / "references";
  }
  const char* home = std::getenv("HOME");
  return std::filesystem::path(home != nullptr && *home != '\0' ? home : "/tmp") / ".cache" / "physval" / "references";
}

std::string reference_cache_key(const Scene& scene, const RunOptions& options) {
  if (scene.source_file.empty()) return {};
  const std::string text = read_bytes(scene.source_file);
  if (text.empty()) return {};
  {
    const std::lock_guard<std::mutex> lock(g_loaded_mutex);
    auto it = g_loaded_text_hash.find(scene.source_file);
    if (it != g_loaded_text_hash.end() && it->second != hash_file_bytes(text)) return {};   // edited since loaded
  }
  std::ostringstream key;
  key << "physval " << PHYSVAL_VERSION << " executable " << executable_hash() << '\n';
  if (const EngineFactory* engine = reference_engine()) {
    key << "reference engine " << engine->info.name << ' ' << engine->info.version << '\n';
    for (const auto& [k, v] : engine->reference_options) key << "reference option " << k << '=' << option_value_to_string(v) << '\n';
  }
  key << "dt " << exact(scene.dt) << " duration " << exact(scene.duration) << " sample_interval "
      << exact(scene.sample_interval) << " max_sample_states " << options.max_sample_states << '\n';
  key << "scenario " << scene.name << ' ' << text.size() << " bytes\n" << text;
  return key.str();
}

CachedReference cached_reference(const Scene& scene, const RunOptions& options) {
  CachedReference out;
  const std::string key = options.reference_cache.empty() ? std::string() : reference_cache_key(scene, options);
  if (key.empty()) {
    out.reference = make_reference(scene, options);
    return out;
  }
  const std::filesystem::path dir = options.reference_cache;
  const std::string name = hash_hex(key) + ".ref";
  if (std::optional<Reference> hit = reference_from(read_bytes(dir / name), key)) {
    out.reference = std::move(*hit);
    out.from_cache = true;
    return out;
  }
  out.reference = make_reference(scene, options);
  // Only a reference that ran is deterministic; a failure (a timeout, a crash) is not stored.
  if (out.reference.available) store(dir, name, key, out.reference);
  return out;
}

}  // namespace physval
