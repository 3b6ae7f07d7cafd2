#include "physval/validation/results_json.hpp"

#include <fcntl.h>
#include <sys/uio.h>
#include <unistd.h>

#include <cerrno>

#include <algorithm>
#include <bit>
#include <charconv>
#include <cmath>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <functional>
#include <map>
#include <memory>
#include <cstring>
#include <string_view>
#include <fstream>
#include <iomanip>
#include <sstream>
#include <unordered_set>
#include <stdexcept>

#include "physval/adapters/registry.hpp"
#include "physval/validation/runner.hpp"
#include "physval/validation/series_file.hpp"

namespace physval {

using nlohmann::json;

namespace {

json opt(const std::optional<double>& v) {
  if (!v || !std::isfinite(*v)) return nullptr;
  return *v;
}
json vec(Vec2 v) { return json::array({v.x, v.y}); }

std::string iso_now() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&now, &tm);
  std::ostringstream os;
  os << std::put_time(&tm, "%Y-%m-%dT%H:%M:%SZ");
  return os.str();
}

std::string safe_file_name(const std::string& s) {
  std::string out;
  for (char c : s) out += (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-') ? c : '_';
  return out;
}

}  // namespace

json context_json() {
  char host[256] = {};
  ::gethostname(host, sizeof host - 1);
  json engines = json::array();
  for (const EngineFactory& f : engine_registry()) {
    engines.push_back({{"name", f.info.name}, {"version", f.info.version}, {"precision", precision_name(f.info.precision)}});
  }
  return {{"physval_version", PHYSVAL_VERSION},
          {"schema_version", 1},
          {"date", iso_now()},
          {"host", host},
          {"build_type", PHYSVAL_BUILD_TYPE},
          {"compiler", std::string("g++ ") + __VERSION__},
          {"engines", engines}};
}

namespace {

json final_state_json(const RunRecord& r, std::size_t i) {
  const BodyState& s = r.final_states[i];
  return {{"body", r.bodies[i].name}, {"position", vec(s.position)}, {"velocity", vec(s.velocity)}, {"alive", s.alive}};
}

json run_to_json_without_lists(const RunRecord& r) {
  json metrics = json::object();
  for (const auto& [k, v] : r.metrics) metrics[k] = opt(v);
  json checks = json::array();
  for (const Check& c : r.checks) {
    checks.push_back({{"what", c.what}, {"limit", c.limit}, {"value", opt(c.value)}, {"pass", c.pass}, {"enforced", c.enforced}});
    if (c.known_failure) checks.back()["known_failure"] = true;
  }
  json settings = json::object();
  for (const auto& [k, v] : r.settings) settings[k] = v;
  json j = {{"scenario", r.scenario},
          {"engine", r.engine},
          {"engine_version", r.engine_version},
          {"precision", r.precision},
          {"dt", r.dt},
          {"steps", r.steps},
          {"status", run_status_name(r.status)},
          {"reason", r.reason},
          {"diverged_at", opt(r.diverged_at)},
          {"known_divergence", r.known_divergence},
          {"wall_seconds", r.wall_seconds},
          {"load_seconds", r.load_seconds},
          {"settings", settings},
          {"limits_hit", r.limits_hit},
          {"metrics", metrics},
          {"checks", checks}};
  if (r.reference_check.applies) {
    const ReferenceCheck& c = r.reference_check;
    j["reference_check"] = {{"judged", c.judged}, {"note", c.note},   {"ratio", opt(c.ratio)}, {"error", opt(c.error)},
                            {"limit", opt(c.limit)}, {"time", opt(c.time)}, {"body", c.body}};
  }
  return j;
}

}  // namespace

json run_to_json(const RunRecord& r) {
  json j = run_to_json_without_lists(r);
  json contacts = json::array();
  for (const ContactRecord& c : r.contacts) contacts.push_back({{"a", c.a}, {"b", c.b}, {"time", c.time}, {"step", c.step}});
  json final_states = json::array();
  for (std::size_t i = 0; i < r.final_states.size() && i < r.bodies.size(); ++i) final_states.push_back(final_state_json(r, i));
  j["contacts"] = std::move(contacts);
  j["final"] = std::move(final_states);
  return j;
}

namespace {

json reference_json_without_contacts(const ScenarioResult& sr) {
  return {{"scenario", sr.scene.name},
          {"available", sr.reference.available},
          {"converged", sr.reference.converged},
          {"reason", sr.reference.reason},
          {"dt", sr.reference.dt},
          {"convergence_error", sr.reference.convergence_error}};
}

json suite_to_json_without_lists(const SuiteResult& result) {
  json comparisons = json::array();
  for (const ScenarioResult& sr : result.scenarios) {
    for (const PairComparison& p : sr.pairs) {
      json m = json::object();
      for (const auto& [k, v] : p.metrics) m[k] = opt(v);
      comparisons.push_back({{"scenario", p.scenario}, {"a", p.a}, {"b", p.b}, {"metrics", m}});
    }
  }
  json out = {{"physval_version", PHYSVAL_VERSION},
              {"context", context_json()},
              {"gates_enforced", result.gates_enforced},
              {"comparisons", comparisons}};
  if (!result.shard.is_null()) out["shard"] = result.shard;
  return out;
}

}  // namespace

json suite_to_json(const SuiteResult& result) {
  json runs = json::array(), references = json::array();
  for (const ScenarioResult& sr : result.scenarios) {
    for (const RunRecord& r : sr.runs) runs.push_back(run_to_json(r));
    json ref = reference_json_without_contacts(sr);
    json contacts = json::array();
    if (sr.reference.run) {
      for (const ContactRecord& c : sr.reference.run->contacts) contacts.push_back({{"a", c.a}, {"b", c.b}, {"time", c.time}});
    }
    ref["contacts"] = contacts;
    references.push_back(ref);
  }
  json out = suite_to_json_without_lists(result);
  out["runs"] = std::move(runs);
  out["references"] = std::move(references);
  return out;
}

void write_file_atomically(const std::filesystem::path& path, std::string_view text) {
  const std::filesystem::path dir = path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
  std::filesystem::create_directories(dir);
  std::string tmp_name = ".";
  tmp_name.append(path.filename().string()).append(".tmp.").append(std::to_string(::getpid()));
  const std::filesystem::path tmp = dir / tmp_name;
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
    out.flush();
    if (!out) {
      std::filesystem::remove(tmp);
      throw std::runtime_error("cannot write " + tmp.string());
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp);
    throw std::runtime_error("cannot rename " + tmp.string() + " to " + path.string() + ": " + ec.message());
  }
}

namespace {

std::filesystem::path sibling(const std::filesystem::path& final_dir, const std::string& tag) {
  std::string name = ".";
  name.append(final_dir.filename().string()).append(".").append(tag).append(".").append(std::to_string(::getpid()));
  return final_dir.parent_path() / name;
}

}  // namespace

StagedOutputFolder::StagedOutputFolder(std::filesystem::path final_dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  final_ = fs::absolute(final_dir, ec).lexically_normal();
  if (ec) throw std::runtime_error(final_dir.string() + ": " + ec.message());
  if (!final_.has_filename()) final_ = final_.parent_path();   // "out/" -> "out"
  const std::string shown = final_dir.string();
  if (fs::exists(final_, ec)) {
    if (!fs::is_directory(final_, ec)) throw std::runtime_error(shown + " exists and is not a folder");
    if (!fs::is_empty(final_, ec) && !fs::exists(final_ / "results.json", ec)) {
      throw std::runtime_error(shown + " is a folder with files but no results.json, so not an earlier physval output; "
                               "physval replaces its output folder whole and will not replace this one (choose another --out)");
    }
  }
  fs::create_directories(final_.parent_path(), ec);
  if (ec) throw std::runtime_error("cannot create " + final_.parent_path().string() + ": " + ec.message());
  staging_ = sibling(final_, "staging");
  fs::remove_all(staging_, ec);
  if (!fs::create_directory(staging_, ec) || ec) {
    throw std::runtime_error("cannot write in " + final_.parent_path().string() + " (for " + shown +
                             "): " + (ec ? ec.message() : std::string("could not create a folder")));
  }
}

StagedOutputFolder::~StagedOutputFolder() {
  if (committed_) return;
  std::error_code ec;
  std::filesystem::remove_all(staging_, ec);
}

void StagedOutputFolder::commit() {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path old = sibling(final_, "old");
  const bool had_old = fs::exists(final_, ec);
  if (had_old) {
    fs::remove_all(old, ec);
    fs::rename(final_, old, ec);
    if (ec) throw std::runtime_error("cannot move the earlier " + final_.string() + " aside: " + ec.message());
  }
  fs::rename(staging_, final_, ec);
  if (ec) {
    if (had_old) fs::rename(old, final_, ec);
    throw std::runtime_error("cannot move " + staging_.string() + " to " + final_.string() + ": " + ec.message());
  }
  committed_ = true;
  if (had_old) fs::remove_all(old, ec);
}

namespace {

// series/<scenario>/scene.json, streamed: on a 100k-body scene a JSON tree of the bodies
// (and a linear search for duplicates) cost more than the harness's whole budget per body.
void write_scene_geometry(std::ostream& os, const ScenarioResult& sr) {
  auto text = [](const std::string& v) { return json(v).dump(); };
  auto number = [](double v) { return json(v).dump(); };
  auto point = [&](Vec2 p) {
    std::string s = "[";  // appended, not "[" + ...: GCC 12's -Wrestrict false positive
    s += number(p.x);
    s += ", ";
    s += number(p.y);
    s += ']';
    return s;
  };
  os << "{\n \"scenario\": " << text(sr.scene.name) << ",\n \"duration\": " << number(sr.scene.duration)
     << ",\n \"dt\": " << number(sr.scene.dt) << ",\n \"bodies\": [";
  // Every body any run had (particles appear in the runs only), in first-seen order.
  std::unordered_set<std::string> seen;
  bool first = true;
  auto body = [&](const std::string& name, double radius, double mass, bool is_static) {
    if (!seen.insert(name).second) return;
    os << (first ? "\n  " : ",\n  ") << "{\"name\": " << text(name) << ", \"radius\": " << number(radius)
       << ", \"mass\": " << number(mass) << ", \"static\": " << (is_static ? "true" : "false") << "}";
    first = false;
  };
  auto add_bodies = [&](const RunRecord& r) {
    for (const BodyMeta& b : r.bodies) body(b.name, b.radius, b.mass, b.is_static);
  };
  if (sr.reference.run) add_bodies(*sr.reference.run);
  for (const RunRecord& r : sr.runs) add_bodies(r);
  for (const BodyDef& b : sr.scene.bodies) body(b.name, b.radius, b.mass, b.is_static);   // a scene no engine ran
  os << "\n ],\n \"walls\": [";
  first = true;
  for (const WallDef& w : sr.scene.walls) {
    os << (first ? "\n  " : ",\n  ") << "{\"name\": " << text(w.name) << ", \"from\": " << point(w.from)
       << ", \"to\": " << point(w.to) << "}";
    first = false;
  }
  os << "\n ],\n \"boxes\": [";
  first = true;
  for (const BoxDef& b : sr.scene.boxes) {
    os << (first ? "\n  " : ",\n  ") << "{\"name\": " << text(b.name) << ", \"min\": " << point(b.min)
       << ", \"max\": " << point(b.max) << "}";
    first = false;
  }
  os << "\n ],\n \"surfaces\": [";
  first = true;
  for (const SurfaceDef& f : sr.scene.surfaces) {
    os << (first ? "\n  " : ",\n  ") << "{\"name\": " << text(f.name) << ", \"points\": [";
    for (std::size_t k = 0; k < f.points.size(); ++k) os << (k ? ", " : "") << point(f.points[k]);
    os << "]}";
    first = false;
  }
  os << "\n ]\n}\n";
}

}  // namespace

json scene_geometry_json(const ScenarioResult& sr) {
  std::ostringstream os;
  write_scene_geometry(os, sr);
  return json::parse(os.str());
}

namespace {

// A file of write_results's own folder, made whole in one write: no temporary name and
// rename as write_file_atomically does, and no ofstream. `physval run` writes into its
// staging folder, which replaces --out whole once everything is written (README, `run`),
// so nothing reads a series file half written; the temporary and the rename were most of
// each small file's syscalls, and the suite writes about 300 of them. A file of two pieces
// (a series file's text lines and its doubles) is written by writev, not joined first.
void write_whole_file(const std::filesystem::path& path, std::string_view head, std::string_view body = {}) {
  const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
  if (fd < 0) throw std::runtime_error("cannot write " + path.string() + ": " + std::strerror(errno));
  std::string_view parts[2] = {head, body};
  std::size_t first = 0;
  auto skip_done = [&] {
    while (first < 2 && parts[first].empty()) ++first;
  };
  skip_done();
  while (first < 2) {
    iovec io[2];
    int n = 0;
    for (std::size_t k = first; k < 2; ++k) io[n++] = {const_cast<char*>(parts[k].data()), parts[k].size()};
    const ssize_t put = ::writev(fd, io, n);
    if (put < 0 && errno == EINTR) continue;
    if (put <= 0) {
      const int e = put < 0 ? errno : EIO;
      ::close(fd);
      throw std::runtime_error("cannot write " + path.string() + ": " + std::strerror(e));
    }
    auto left = static_cast<std::size_t>(put);
    for (; first < 2 && left > 0; ++first) {
      const std::size_t k = std::min(left, parts[first].size());
      parts[first].remove_prefix(k);
      left -= k;
      if (!parts[first].empty()) break;
    }
    skip_done();
  }
  if (::close(fd) != 0) throw std::runtime_error("cannot write " + path.string() + ": " + std::strerror(errno));
}

}  // namespace

void write_results(const std::filesystem::path& dir, const SuiteResult& result, SeriesFormat format) {
  // Series first: results.json, written last, is what marks a complete output.
  std::vector<double> values;   // one buffer for all series: its pages are faulted in once
  std::unique_ptr<char[]> text;   // --series-csv: the text, likewise
  std::size_t text_capacity = 0;
  for (const ScenarioResult& sr : result.scenarios) {
    const double cpu0 = thread_cpu_seconds();
    const std::filesystem::path folder = dir / "series" / safe_file_name(sr.scene.name);
    std::filesystem::create_directories(folder);
    {
      std::ostringstream geometry;
      write_scene_geometry(geometry, sr);
      write_whole_file(folder / "scene.json", geometry.str());
    }
    auto write_series = [&](const RunRecord& r, const std::string& label) {
      if (r.series.time.empty()) return;
      const std::string header = series_header(r);
      const std::size_t columns = series_values(r, values);
      const std::size_t rows = r.series.time.size();
      if (format == SeriesFormat::Binary) {
        // The doubles as they are (series_file.hpp): no text to make, half the CSV's bytes.
        std::string_view body(reinterpret_cast<const char*>(values.data()), values.size() * sizeof(double));
        std::string swapped;
        if constexpr (std::endian::native == std::endian::big) {
          append_series_binary(swapped, header, values.data(), rows, columns);
          write_whole_file(folder / (safe_file_name(label) + ".bin"), swapped);
          return;
        }
        write_whole_file(folder / (safe_file_name(label) + ".bin"), series_binary_prefix(header, rows, columns), body);
        return;
      }
      const std::size_t capacity = series_csv_capacity(header.size(), rows, columns);
      if (capacity > text_capacity) {
        text.reset(new char[capacity]);   // not zeroed: written before read
        text_capacity = capacity;
      }
      const char* end = write_series_csv(text.get(), header, values.data(), rows, columns);
      write_whole_file(folder / (safe_file_name(label) + ".csv"),
                       std::string_view(text.get(), static_cast<std::size_t>(end - text.get())));
    };
    for (const RunRecord& r : sr.runs) write_series(r, r.engine);
    if (sr.reference.run) write_series(*sr.reference.run, "reference");
    sr.write_cpu_seconds = thread_cpu_seconds() - cpu0;
  }
  write_results_json(dir / "results.json", result);
}

namespace {

// results.json streamed: the text suite_to_json(result).dump(2) gives, byte for byte,
// written piece by piece, so that no JSON tree of every run's contacts and final states
// exists at once (on a 100k-body gas that tree was several kB a body).
class JsonStream {
 public:
  explicit JsonStream(std::ostream& os) : os_(os) {}
  // A value at nesting depth `depth` (its first line is already placed).
  void value(const json& v, int depth) {
    const std::string text = v.dump(2);
    const std::string pad(static_cast<std::size_t>(2 * depth), ' ');
    std::size_t from = 0;
    for (std::size_t nl = text.find('\n'); nl != std::string::npos; nl = text.find('\n', from)) {
      os_.write(text.data() + from, static_cast<std::streamsize>(nl + 1 - from));
      os_ << pad;
      from = nl + 1;
    }
    os_.write(text.data() + from, static_cast<std::streamsize>(text.size() - from));
  }
  // An array whose elements come from `element(i)`, at depth `depth`.
  template <class Element>
  void array(std::size_t n, int depth, Element element) {
    if (n == 0) {
      os_ << "[]";
      return;
    }
    const std::string pad(static_cast<std::size_t>(2 * (depth + 1)), ' ');
    os_ << "[\n";
    for (std::size_t i = 0; i < n; ++i) {
      os_ << pad;
      element(i, depth + 1);
      os_ << (i + 1 < n ? ",\n" : "\n");
    }
    os_ << std::string(static_cast<std::size_t>(2 * depth), ' ') << ']';
  }
  // An array of contacts at depth `depth`: the text array() with contact() gives, byte for
  // byte, built in one buffer from each element's fixed pieces (results.json holds every
  // contact of every run and reference: about 100k in the built-in suite, where writing
  // them piece by piece through the stream was a tenth of the harness).
  void contact_array(const std::vector<ContactRecord>& cs, bool with_step, int depth) {
    if (cs.empty()) {
      os_ << "[]";
      return;
    }
    // Appended piece by piece, not "..." + std::string: GCC 12's -Wrestrict false positive.
    const std::size_t pad = static_cast<std::size_t>(2 * (depth + 1));
    auto line = [&](const char* head, std::size_t spaces, const char* tail) {
      std::string piece(head);
      piece.append(spaces, ' ');
      piece.append(tail);
      return piece;
    };
    std::string open(pad, ' ');
    open.append(line("{\n", pad + 2, "\"a\": "));
    const std::string after_a = line(",\n", pad + 2, "\"b\": ");
    const std::string to_step = line(",\n", pad + 2, "\"step\": ");
    const std::string to_time = line(",\n", pad + 2, "\"time\": ");
    const std::string close = line("\n", pad, "}");
    // Each contact's text is put at a cursor into text_, made large enough for the contact
    // first (its fixed pieces, its names and a time and step of at most 64 characters each,
    // or the names' escaped text), then cut to what was written before a flush.
    std::string& t = text_;
    t.assign("[\n");
    std::size_t used = t.size();
    const std::size_t fixed = open.size() + after_a.size() + to_step.size() + to_time.size() + close.size() + 2 + 64 + 24;
    auto put = [&](const std::string& piece) {
      std::memcpy(t.data() + used, piece.data(), piece.size());
      used += piece.size();
    };
    char time_text[64];
    std::size_t time_text_size = 0;
    double last_time = 0.0;
    bool have_time = false;
    for (std::size_t k = 0; k < cs.size(); ++k) {
      const ContactRecord& c = cs[k];
      const std::size_t room = fixed + 2 * (c.a.size() + c.b.size()) + 4;
      if (used + room > t.size()) t.resize(std::max(used + room, 2 * t.size()));
      put(open);
      put_string_at(t, used, c.a);
      put(after_a);
      put_string_at(t, used, c.b);
      if (with_step) {
        put(to_step);
        used = static_cast<std::size_t>(std::to_chars(t.data() + used, t.data() + used + 24, static_cast<std::int64_t>(c.step)).ptr - t.data());
      }
      put(to_time);
      if (std::isfinite(c.time)) {
        // A run's contacts come in time order, many in one step at the same time (every
        // contact a step-end engine reports in a step): the text of the time before is
        // reused when the double is the same, bit for bit.
        if (!(have_time && std::memcmp(&c.time, &last_time, sizeof last_time) == 0)) {
          time_text_size = static_cast<std::size_t>(nlohmann::detail::to_chars(time_text, time_text + sizeof time_text, c.time) - time_text);
          last_time = c.time;
          have_time = true;
        }
        std::memcpy(t.data() + used, time_text, time_text_size);
        used += time_text_size;
      } else {
        std::memcpy(t.data() + used, "null", 4);
        used += 4;
      }
      put(close);
      std::memcpy(t.data() + used, k + 1 < cs.size() ? ",\n" : "\n", k + 1 < cs.size() ? 2 : 1);
      used += k + 1 < cs.size() ? 2 : 1;
      if (used >= (std::size_t{1} << 16)) {
        os_.write(t.data(), static_cast<std::streamsize>(used));
        used = 0;
      }
    }
    t.resize(used);
    t.append(static_cast<std::size_t>(2 * depth), ' ');
    t += ']';
    os_.write(t.data(), static_cast<std::streamsize>(t.size()));
  }
  // An object of the keys of `small` and the `big` keys written by their functions, in
  // nlohmann's (sorted) key order.
  void object(const json& small, const std::map<std::string, std::function<void(int)>>& big, int depth) {
    std::vector<std::string> keys;
    for (const auto& [k, v] : small.items()) keys.push_back(k);
    for (const auto& [k, f] : big) keys.push_back(k);
    std::sort(keys.begin(), keys.end());
    if (keys.empty()) {
      os_ << "{}";
      return;
    }
    const std::string pad(static_cast<std::size_t>(2 * (depth + 1)), ' ');
    os_ << "{\n";
    for (std::size_t i = 0; i < keys.size(); ++i) {
      os_ << pad << json(keys[i]).dump() << ": ";
      if (auto it = big.find(keys[i]); it != big.end()) {
        it->second(depth + 1);
      } else {
        value(small.at(keys[i]), depth + 1);
      }
      os_ << (i + 1 < keys.size() ? ",\n" : "\n");
    }
    os_ << std::string(static_cast<std::size_t>(2 * depth), ' ') << '}';
  }

 private:
  // A JSON string as nlohmann's dump writes it, at t[used], where room for twice the
  // name's size and its quotes was made: plain printable ASCII as it is, anything else
  // (escapes, UTF-8) by nlohmann itself (rare: t grows by its text).
  static void put_string_at(std::string& t, std::size_t& used, const std::string& v) {
    for (const char ch : v) {
      const auto u = static_cast<unsigned char>(ch);
      if (u < 0x20 || u >= 0x7f || ch == '"' || ch == '\\') {
        const std::string text = json(v).dump();
        t.resize(t.size() + text.size());   // the room made for the contact's other pieces is kept
        std::memcpy(t.data() + used, text.data(), text.size());
        used += text.size();
        return;
      }
    }
    t[used++] = '"';
    std::memcpy(t.data() + used, v.data(), v.size());
    used += v.size();
    t[used++] = '"';
  }

  std::ostream& os_;
  std::string text_;
};

}  // namespace

void write_results_json(std::ostream& os, const SuiteResult& result) {
  JsonStream out(os);
  std::vector<const RunRecord*> runs;
  std::vector<const ScenarioResult*> run_scenario;
  for (const ScenarioResult& sr : result.scenarios) {
    for (const RunRecord& r : sr.runs) {
      runs.push_back(&r);
      run_scenario.push_back(&sr);
    }
  }
  // Each run without its two long lists, which are streamed element by element.
  auto run_json = [&](std::size_t i, int depth) {
    const double cpu0 = thread_cpu_seconds();
    const RunRecord& r = *runs[i];
    json small = run_to_json_without_lists(r);
    std::map<std::string, std::function<void(int)>> big;
    big["contacts"] = [&](int d) { out.contact_array(r.contacts, true, d); };
    big["final"] = [&](int d) {
      const std::size_t n = std::min(r.final_states.size(), r.bodies.size());
      out.array(n, d, [&](std::size_t k, int dd) { out.value(final_state_json(r, k), dd); });
    };
    out.object(small, big, depth);
    run_scenario[i]->write_cpu_seconds += thread_cpu_seconds() - cpu0;
  };
  json small = suite_to_json_without_lists(result);
  std::map<std::string, std::function<void(int)>> big;
  big["runs"] = [&](int d) { out.array(runs.size(), d, run_json); };
  big["references"] = [&](int d) {
    out.array(result.scenarios.size(), d, [&](std::size_t s, int dd) {
      const double cpu0 = thread_cpu_seconds();
      const ScenarioResult& sr = result.scenarios[s];
      json ref = reference_json_without_contacts(sr);
      std::map<std::string, std::function<void(int)>> contacts;
      contacts["contacts"] = [&](int d3) {
        static const std::vector<ContactRecord> none;
        out.contact_array(sr.reference.run ? sr.reference.run->contacts : none, false, d3);
      };
      out.object(ref, contacts, dd);
      sr.write_cpu_seconds += thread_cpu_seconds() - cpu0;
    });
  };
  out.object(small, big, 0);
  os << '\n';
}

void write_results_json(const std::filesystem::path& path, const SuiteResult& result) {
  // Written beside, then renamed into place, as write_file_atomically does.
  const std::filesystem::path dir = path.parent_path().empty() ? std::filesystem::path(".") : path.parent_path();
  std::filesystem::create_directories(dir);
  const std::filesystem::path tmp = dir / ("." + path.filename().string() + ".tmp." + std::to_string(::getpid()));
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
    write_results_json(out, result);
    out.flush();
    if (!out) {
      std::filesystem::remove(tmp);
      throw std::runtime_error("cannot write " + tmp.string());
    }
  }
  std::error_code ec;
  std::filesystem::rename(tmp, path, ec);
  if (ec) {
    std::filesystem::remove(tmp);
    throw std::runtime_error("cannot rename " + tmp.string() + " to " + path.string() + ": " + ec.message());
  }
}

nlohmann::json overhead_json(const SuiteResult& result, double process_cpu_seconds) {
  json scenarios = json::array();
  double sum_wall = 0.0, sum_step = 0.0, sum_ref = 0.0, sum_over = 0.0;
  for (const ScenarioResult& sr : result.scenarios) {
    double wall = 0.0, step = 0.0, child = 0.0, parent = 0.0;
    for (const RunRecord& r : sr.runs) {
      wall += r.wall_seconds;
      step += r.step_cpu_seconds;
      child += r.child_cpu_seconds;
      parent += r.parent_cpu_seconds;
    }
    // The runs' harness: their children's and the parent's CPU beyond the stepping.
    const double runs_harness = child + parent - step;
    const double overhead = runs_harness + sr.compare_cpu_seconds + sr.write_cpu_seconds;
    scenarios.push_back({{"scenario", sr.scene.name},
                         {"runs", sr.runs.size()},
                         {"stepping_wall_seconds", wall},
                         {"stepping_cpu_seconds", step},
                         {"reference_cpu_seconds", sr.reference_cpu_seconds},
                         {"runs_harness_cpu_seconds", runs_harness},
                         {"compare_cpu_seconds", sr.compare_cpu_seconds},
                         {"write_cpu_seconds", sr.write_cpu_seconds},
                         {"overhead_cpu_seconds", overhead},
                         {"overhead_percent", step > 0.0 ? json(100.0 * overhead / step) : json(nullptr)}});
    sum_wall += wall;
    sum_step += step;
    sum_ref += sr.reference_cpu_seconds;
    sum_over += overhead;
  }
  const double unattributed = process_cpu_seconds - sum_step - sum_ref - sum_over;
  const double total_over = sum_over + unattributed;
  return {{"definition",
           "overhead = CPU of physval and its engine children minus the engines' stepping (CPU inside "
           "step()) and the references (computed or read from the cache); per scenario: its runs' children "
           "and parent-side CPU beyond stepping, its comparisons and its writing; the suite adds what no "
           "scenario is charged with (start, loading, table)"},
          {"scenarios", scenarios},
          {"suite",
           {{"stepping_wall_seconds", sum_wall},
            {"stepping_cpu_seconds", sum_step},
            {"reference_cpu_seconds", sum_ref},
            {"scenarios_overhead_cpu_seconds", sum_over},
            {"unattributed_cpu_seconds", unattributed},
            {"process_cpu_seconds", process_cpu_seconds},
            {"overhead_cpu_seconds", total_over},
            {"overhead_percent", sum_step > 0.0 ? json(100.0 * total_over / sum_step) : json(nullptr)}}}};
}

}  // namespace physval
