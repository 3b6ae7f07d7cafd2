#include "physval/validation/shard.hpp"

#include <dlfcn.h>
#include <link.h>

#include <algorithm>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iterator>
#include <numeric>
#include <set>

#include "physval/adapters/registry.hpp"
#include "physval/validation/reference_cache.hpp"

namespace physval {

std::optional<ShardSpec> parse_shard(const std::string& text, std::string& error) {
  const auto slash = text.find('/');
  auto whole = [](const std::string& s, std::size_t& out) {
    if (s.empty() || s.size() > 9 || !std::all_of(s.begin(), s.end(), [](char c) { return c >= '0' && c <= '9'; })) {
      return false;
    }
    out = static_cast<std::size_t>(std::stoul(s));
    return true;
  };
  ShardSpec spec;
  if (slash == std::string::npos || !whole(text.substr(0, slash), spec.index) || !whole(text.substr(slash + 1), spec.count)) {
    error = "--shard: expected I/N with whole numbers, 0 <= I < N (such as 0/4), got \"" + text + "\"";
    return std::nullopt;
  }
  if (spec.count == 0 || spec.index >= spec.count) {
    error = "--shard " + text + ": I must be in 0..N-1 (shards are numbered from 0, like SLURM_ARRAY_TASK_ID)";
    return std::nullopt;
  }
  return spec;
}

std::vector<std::size_t> assign_shards(const std::vector<double>& costs, std::size_t count) {
  std::vector<std::size_t> shard(costs.size(), 0);
  if (count <= 1) return shard;
  std::vector<std::size_t> order(costs.size());
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return costs[a] > costs[b]; });
  std::vector<double> load(count, 0.0);
  for (std::size_t item : order) {
    const std::size_t least = static_cast<std::size_t>(std::min_element(load.begin(), load.end()) - load.begin());
    shard[item] = least;
    load[least] += std::max(0.0, costs[item]);
  }
  return shard;
}

double scenario_cost(const Scene& scene, std::size_t engine_runs) {
  const double body_steps =
      static_cast<double>(std::max<std::size_t>(1, scene.bodies.size())) * static_cast<double>(scene.steps());
  return body_steps * (12.0 + static_cast<double>(engine_runs));
}

std::string file_fingerprint(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return "";
  std::uint64_t h = 1469598103934665603ull;
  char buf[65536];
  while (in.read(buf, sizeof buf) || in.gcount() > 0) {
    for (std::streamsize i = 0; i < in.gcount(); ++i) {
      h ^= static_cast<unsigned char>(buf[i]);
      h *= 1099511628211ull;
    }
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

namespace {

// The files of the loaded shared objects that export a physval plugin table.
int collect_plugin_file(dl_phdr_info* info, std::size_t, void* data) {
  if (info->dlpi_name == nullptr || info->dlpi_name[0] == '\0') return 0;
  void* handle = ::dlopen(info->dlpi_name, RTLD_NOW | RTLD_NOLOAD);
  if (handle == nullptr) return 0;
  if (::dlsym(handle, "physval_plugin_v1") != nullptr) static_cast<std::set<std::string>*>(data)->insert(info->dlpi_name);
  ::dlclose(handle);
  return 0;
}

}  // namespace

nlohmann::json build_identity() {
  nlohmann::json engines = nlohmann::json::array();
  for (const EngineFactory& f : engine_registry()) {
    engines.push_back({{"name", f.info.name}, {"version", f.info.version}, {"precision", precision_name(f.info.precision)}});
  }
  std::set<std::string> files;
  ::dl_iterate_phdr(collect_plugin_file, &files);
  std::set<std::string> hashes;   // by content: the same library at another path is the same build
  for (const std::string& file : files) {
    std::ifstream in(file, std::ios::binary);
    hashes.insert(in ? hash_file_bytes(std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()))
                     : "unreadable");
  }
  return {{"executable", executable_hash()},
          {"engines", engines},
          {"plugin_libraries", nlohmann::json(std::vector<std::string>(hashes.begin(), hashes.end()))}};
}

}  // namespace physval
