// Packs a scenario's series for the report's scene player (see report_player.hpp for
// the coding, report_player_script.cpp for the browser side that undoes it).
//
// The blob, per source (reference first, then engines, as in the header's "sources"):
//   positions: for each body, for each frame, x then y, each a varint: 0 = the body is
//              not there (not yet spawned, destroyed), else zigzag(q - previous q) + 1,
//              q = round((coordinate - origin) / quantum), previous q starting at 0;
//   energy:    one float32 (little-endian) per frame: E(t) - E(0), NaN where unknown
//              (E(0) is the header's source "e0");
//   contacts:  varint count, then per contact (sorted by time) varint a, varint b
//              (indexes into the header's "objects": bodies, then barriers) and varint
//              time - previous time in ticks of duration / 2^20.
#include "report_player.hpp"

#include <zlib.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <map>
#include <stdexcept>

#include "markup_escape.hpp"

namespace physval::report_detail {

namespace {

constexpr double kContactTicks = 1048576.0;   // 2^20 per duration

void put_varint(std::string& out, std::uint64_t v) {
  while (v >= 0x80) {
    out += static_cast<char>((v & 0x7f) | 0x80);
    v >>= 7;
  }
  out += static_cast<char>(v);
}

std::uint64_t zigzag(std::int64_t v) {
  return (static_cast<std::uint64_t>(v) << 1) ^ static_cast<std::uint64_t>(v >> 63);
}

void put_float32(std::string& out, double v) {
  const float f = static_cast<float>(v);
  std::uint32_t bits = 0;
  std::memcpy(&bits, &f, sizeof bits);
  for (int i = 0; i < 4; ++i) out += static_cast<char>((bits >> (8 * i)) & 0xff);
}

// A column resampled at the frame times: linear between two finite neighbours, the
// nearer finite one at an edge of a gap, NaN where neither is.
std::vector<double> resample(const std::vector<double>& t, const std::vector<double>* col, const std::vector<double>& at) {
  std::vector<double> out(at.size(), NAN);
  if (col == nullptr || t.empty()) return out;
  for (std::size_t k = 0; k < at.size(); ++k) {
    const auto it = std::lower_bound(t.begin(), t.end(), at[k]);
    const std::size_t hi = static_cast<std::size_t>(std::min<std::ptrdiff_t>(it - t.begin(), static_cast<std::ptrdiff_t>(t.size()) - 1));
    const std::size_t lo = hi > 0 && t[hi] > at[k] ? hi - 1 : hi;
    const double a = (*col)[lo], b = (*col)[hi];
    if (lo == hi || !(t[hi] > t[lo])) {
      out[k] = std::isfinite(b) ? b : a;
    } else if (std::isfinite(a) && std::isfinite(b)) {
      const double w = (at[k] - t[lo]) / (t[hi] - t[lo]);
      out[k] = a + (b - a) * std::clamp(w, 0.0, 1.0);
    } else {
      const bool nearer_hi = at[k] - t[lo] > t[hi] - at[k];
      out[k] = nearer_hi ? (std::isfinite(b) ? b : NAN) : (std::isfinite(a) ? a : NAN);
    }
  }
  return out;
}

struct Box {
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  void add(double x, double y) {
    if (!std::isfinite(x) || !std::isfinite(y)) return;
    x0 = std::min(x0, x);
    y0 = std::min(y0, y);
    x1 = std::max(x1, x);
    y1 = std::max(y1, y);
  }
  bool empty() const { return !(x0 <= x1 && y0 <= y1); }
};

}  // namespace

std::string base64(const std::string& bytes) {
  static const char* kAlphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const std::uint32_t n = (static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i])) << 16) |
                            (static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8) |
                            static_cast<unsigned char>(bytes[i + 2]);
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += kAlphabet[(n >> 6) & 63];
    out += kAlphabet[n & 63];
  }
  if (i < bytes.size()) {
    std::uint32_t n = static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i])) << 16;
    if (i + 1 < bytes.size()) n |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[i + 1])) << 8;
    out += kAlphabet[(n >> 18) & 63];
    out += kAlphabet[(n >> 12) & 63];
    out += i + 1 < bytes.size() ? kAlphabet[(n >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string deflate_zlib(const std::string& bytes) {
  uLongf size = compressBound(static_cast<uLong>(bytes.size()));
  std::string out(size, '\0');
  const int rc = compress2(reinterpret_cast<Bytef*>(out.data()), &size, reinterpret_cast<const Bytef*>(bytes.data()),
                           static_cast<uLong>(bytes.size()), 9);
  if (rc != Z_OK) throw std::runtime_error("zlib compress2 failed (" + std::to_string(rc) + ")");
  out.resize(size);
  return out;
}

PlayerSection player_section(const ScenarioView& v, const std::vector<std::string>& engines, const std::string& anchor) {
  PlayerSection section;
  const json& geometry = v.geometry;

  // Bodies: the geometry's (every body any run had), then any a series names beside them.
  std::vector<std::string> bodies;
  std::map<std::string, double> radius;
  std::map<std::string, bool> is_static;
  if (member(geometry, "bodies").is_array()) {
    for (const json& b : geometry["bodies"]) {
      const std::string name = str(b, "name");
      if (name.empty() || radius.count(name)) continue;
      bodies.push_back(name);
      radius[name] = num(b, "radius").value_or(0.0);
      is_static[name] = member(b, "static").is_boolean() && b["static"].get<bool>();
    }
  }
  for (const Source& s : v.sources) {
    for (const std::string& name : s.table.bodies()) {
      if (radius.count(name)) continue;
      bodies.push_back(name);
      radius[name] = 0.0;
    }
  }

  // Frames: evenly spaced over the longest source, at most kMaxFrames, and fewer for
  // many bodies so that a page stays light (about 1.2 M coordinates a scenario).
  double t_end = 0.0;
  std::size_t rows = 0;
  for (const Source& s : v.sources) {
    if (const auto* t = s.table.column("t"); t && !t->empty()) {
      t_end = std::max(t_end, t->back());
      rows = std::max(rows, t->size());
    }
  }
  const std::size_t coordinate_budget = 1'200'000;
  const std::size_t per_frame = std::max<std::size_t>(1, 2 * bodies.size() * v.sources.size());
  std::size_t frames = std::min({rows, kMaxFrames, std::max<std::size_t>(60, coordinate_budget / per_frame)});
  frames = std::max<std::size_t>(frames, 2);
  std::vector<double> at(frames);
  for (std::size_t k = 0; k < frames; ++k) at[k] = t_end * static_cast<double>(k) / static_cast<double>(frames - 1);

  // Resample every source; the extent covers the positions and the barriers.
  struct Resampled {
    std::vector<std::vector<double>> x, y;   // [body][frame]
    std::vector<double> energy;
  };
  std::vector<Resampled> resampled;
  Box box;
  for (const Source& s : v.sources) {
    Resampled r;
    static const std::vector<double> kNoTime;
    const auto* t = s.table.column("t");
    const std::vector<double>& time = t ? *t : kNoTime;
    for (const std::string& name : bodies) {
      r.x.push_back(resample(time, s.table.column("x_" + name), at));
      r.y.push_back(resample(time, s.table.column("y_" + name), at));
      for (std::size_t k = 0; k < frames; ++k) box.add(r.x.back()[k], r.y.back()[k]);
    }
    r.energy = resample(time, s.table.column("energy"), at);
    resampled.push_back(std::move(r));
  }
  json walls = json::array(), boxes = json::array(), surfaces = json::array();
  std::vector<std::string> barrier_names;
  auto point = [](const json& p) { return p.is_array() && p.size() == 2 && p[0].is_number() && p[1].is_number(); };
  for (const json& w : member(geometry, "walls").is_array() ? geometry["walls"] : json::array()) {
    if (!point(member(w, "from")) || !point(member(w, "to"))) continue;
    walls.push_back({w["from"][0], w["from"][1], w["to"][0], w["to"][1]});
    box.add(w["from"][0].get<double>(), w["from"][1].get<double>());
    box.add(w["to"][0].get<double>(), w["to"][1].get<double>());
    barrier_names.push_back(str(w, "name"));
  }
  for (const json& b : member(geometry, "boxes").is_array() ? geometry["boxes"] : json::array()) {
    if (!point(member(b, "min")) || !point(member(b, "max"))) continue;
    boxes.push_back({b["min"][0], b["min"][1], b["max"][0], b["max"][1]});
    box.add(b["min"][0].get<double>(), b["min"][1].get<double>());
    box.add(b["max"][0].get<double>(), b["max"][1].get<double>());
    barrier_names.push_back(str(b, "name"));
  }
  for (const json& s : member(geometry, "surfaces").is_array() ? geometry["surfaces"] : json::array()) {
    json flat = json::array();
    for (const json& p : member(s, "points").is_array() ? s["points"] : json::array()) {
      if (!point(p)) continue;
      flat.push_back(p[0]);
      flat.push_back(p[1]);
      box.add(p[0].get<double>(), p[1].get<double>());
    }
    if (flat.size() >= 4) {
      surfaces.push_back(flat);
      barrier_names.push_back(str(s, "name"));
    }
  }
  // Bodies drawn with their radius: the extent reaches their edges.
  double largest_radius = 0.0;
  for (const auto& [name, r] : radius) largest_radius = std::max(largest_radius, r);
  if (box.empty()) box.add(0.0, 0.0);
  box.x0 -= largest_radius;
  box.y0 -= largest_radius;
  box.x1 += largest_radius;
  box.y1 += largest_radius;
  const double span = std::max({box.x1 - box.x0, box.y1 - box.y0, 1e-9});
  const double quantum = span / kQuantizationSteps;

  // The objects contacts name: bodies, then barriers.
  std::map<std::string, std::size_t> object_index;
  json objects = json::array();
  for (const std::string& b : bodies) {
    object_index.emplace(b, objects.size());
    objects.push_back(b);
  }
  for (const std::string& b : barrier_names) {
    object_index.emplace(b, objects.size());
    objects.push_back(b);
  }
  auto contacts_of = [&](const json* holder) {
    std::vector<std::array<double, 3>> out;
    if (holder == nullptr || !member(*holder, "contacts").is_array()) return out;
    for (const json& c : (*holder)["contacts"]) {
      const auto t = num(c, "time");
      const auto a = object_index.find(str(c, "a")), b = object_index.find(str(c, "b"));
      if (!t || a == object_index.end() || b == object_index.end()) continue;
      out.push_back({static_cast<double>(a->second), static_cast<double>(b->second), *t});
    }
    std::stable_sort(out.begin(), out.end(), [](const auto& p, const auto& q) { return p[2] < q[2]; });
    return out;
  };

  std::string coded;
  json sources = json::array();
  for (std::size_t s = 0; s < v.sources.size(); ++s) {
    const Source& src = v.sources[s];
    const Resampled& r = resampled[s];
    for (std::size_t b = 0; b < bodies.size(); ++b) {
      std::int64_t prev_x = 0, prev_y = 0;
      for (std::size_t k = 0; k < frames; ++k) {
        const double x = r.x[b][k], y = r.y[b][k];
        if (!std::isfinite(x) || !std::isfinite(y)) {
          coded += '\0';
          coded += '\0';
          continue;
        }
        const std::int64_t qx = std::llround((x - box.x0) / quantum), qy = std::llround((y - box.y0) / quantum);
        put_varint(coded, zigzag(qx - prev_x) + 1);
        put_varint(coded, zigzag(qy - prev_y) + 1);
        prev_x = qx;
        prev_y = qy;
      }
    }
    // Energy as E(t) - E(0), subtracted in double: a drift at round-off (1e-13 J of 40 J)
    // survives float32, which E(t) itself would not.
    double e0 = NAN;
    if (const auto* e = src.table.column("energy")) {
      for (double value : *e) {
        if (std::isfinite(value)) {
          e0 = value;
          break;
        }
      }
    }
    for (std::size_t k = 0; k < frames; ++k) put_float32(coded, r.energy[k] - e0);
    const json* holder = nullptr;
    if (src.engine.empty()) {
      holder = v.reference;
    } else {
      for (const json* run : v.runs) {
        if (str(*run, "engine") == src.engine) holder = run;
      }
    }
    const auto contacts = contacts_of(holder);
    put_varint(coded, contacts.size());
    std::int64_t prev_tick = 0;
    for (const auto& c : contacts) {
      const std::int64_t tick = t_end > 0.0 ? std::llround(c[2] / t_end * kContactTicks) : 0;
      put_varint(coded, static_cast<std::uint64_t>(c[0]));
      put_varint(coded, static_cast<std::uint64_t>(c[1]));
      put_varint(coded, static_cast<std::uint64_t>(std::max<std::int64_t>(0, tick - prev_tick)));
      prev_tick = std::max(prev_tick, tick);
    }
    const bool reference = src.engine.empty();
    sources.push_back({{"label", src.label},
                       {"engine", src.engine},
                       {"e0", std::isfinite(e0) ? json(e0) : json(nullptr)},
                       {"colour", reference ? std::string(kReferenceColour) : engine_colour(engines, src.engine)}});
    section.raw_bytes += frames * bodies.size() * 2 * 8 + frames * 8 + contacts.size() * 3 * 8;
  }

  json body_list = json::array();
  for (const std::string& b : bodies) body_list.push_back({b, radius[b], is_static[b] ? 1 : 0});
  const json header = {{"scenario", v.name},
                       {"duration", t_end},
                       {"frames", frames},
                       {"origin", {box.x0, box.y0}},
                       {"quantum", quantum},
                       {"extent", {box.x0, box.y0, box.x1, box.y1}},
                       {"contact_ticks", kContactTicks},
                       {"bodies", body_list},
                       {"objects", objects},
                       {"walls", walls},
                       {"boxes", boxes},
                       {"surfaces", surfaces},
                       {"sources", sources}};
  const std::string packed = deflate_zlib(coded);
  const std::string text = base64(packed);
  section.frames = frames;
  section.bodies = bodies.size();
  section.coded_bytes = coded.size();
  section.packed_bytes = packed.size();
  section.embedded_bytes = text.size();

  // "</" would end the <script> element early: JSON allows "<\/".
  std::string header_text;
  for (char c : header.dump()) {
    if (c == '/' && !header_text.empty() && header_text.back() == '<') header_text += '\\';
    header_text += c;
  }
  section.html = "<div class=player id=\"" + markup_escape(anchor) + "\" data-scenario=\"" + markup_escape(v.name) +
                 "\"><script type=\"application/json\" class=player-header>" + header_text +
                 "</script><script type=\"text/plain\" class=player-data>" + text +
                 "</script><p class=note>The scene player needs JavaScript.</p></div>\n";
  return section;
}

}  // namespace physval::report_detail
