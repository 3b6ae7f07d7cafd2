// The scene player's data, decoded here the way the page's script decodes it (base64,
// zlib, varints, deltas): every position comes back within half a quantum, bodies that
// are not there come back absent, energies and contacts survive; and the figures that
// read the same geometry draw the barriers.
#include <gtest/gtest.h>
#include <zlib.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <regex>
#include <string>
#include <vector>

#include "../src/report_figures.hpp"
#include "../src/report_player.hpp"

namespace physval::report_detail {
namespace {

std::string unbase64(const std::string& text) {
  std::string out;
  std::uint32_t buffer = 0;
  int bits = 0;
  for (char c : text) {
    int v = -1;
    if (c >= 'A' && c <= 'Z') v = c - 'A';
    if (c >= 'a' && c <= 'z') v = c - 'a' + 26;
    if (c >= '0' && c <= '9') v = c - '0' + 52;
    if (c == '+') v = 62;
    if (c == '/') v = 63;
    if (v < 0) continue;
    buffer = (buffer << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out += static_cast<char>((buffer >> bits) & 0xff);
    }
  }
  return out;
}

std::string inflate(const std::string& packed) {
  std::string out(1 << 22, '\0');
  uLongf size = static_cast<uLongf>(out.size());
  EXPECT_EQ(uncompress(reinterpret_cast<Bytef*>(out.data()), &size, reinterpret_cast<const Bytef*>(packed.data()),
                       static_cast<uLong>(packed.size())),
            Z_OK);
  out.resize(size);
  return out;
}

struct Reader {
  const std::string& bytes;
  std::size_t at = 0;
  std::uint64_t varint() {
    std::uint64_t v = 0;
    for (int shift = 0;; shift += 7) {
      EXPECT_LT(at, bytes.size());
      if (at >= bytes.size()) return 0;
      const auto b = static_cast<unsigned char>(bytes[at++]);
      v |= static_cast<std::uint64_t>(b & 0x7f) << shift;
      if (!(b & 0x80)) return v;
    }
  }
  float float32() {
    std::uint32_t bits = 0;
    for (int i = 0; i < 4; ++i) bits |= static_cast<std::uint32_t>(static_cast<unsigned char>(bytes[at++])) << (8 * i);
    float f;
    std::memcpy(&f, &bits, sizeof f);
    return f;
  }
};

std::int64_t unzigzag(std::uint64_t z) { return (z & 1) ? -static_cast<std::int64_t>((z + 1) / 2) : static_cast<std::int64_t>(z / 2); }

// Two bodies over 50 samples: "a" on a circle far from the origin, "b" gone after t = 0.3.
Source source(const std::string& label, const std::string& engine, double wobble) {
  Source s{label, engine, {}};
  s.table.names = {"t", "energy", "x_a", "y_a", "x_b", "y_b"};
  s.table.columns.resize(6);
  for (int k = 0; k < 50; ++k) {
    const double t = 0.02 * k;
    s.table.columns[0].push_back(t);
    s.table.columns[1].push_back(40.0 + wobble * t);
    s.table.columns[2].push_back(1e4 + std::cos(3 * t) + wobble);
    s.table.columns[3].push_back(-5.0 + std::sin(3 * t));
    s.table.columns[4].push_back(t <= 0.3 ? 1e4 + 0.5 * t : NAN);
    s.table.columns[5].push_back(t <= 0.3 ? -5.0 : NAN);
  }
  return s;
}

ScenarioView view_with_geometry() {
  ScenarioView v;
  v.name = "roundtrip";
  v.duration = 0.98;
  v.sources.push_back(source("reference", "", 0.0));
  v.sources.push_back(source("box2d", "box2d", 1e-3));
  v.geometry = json::parse(R"({"bodies": [{"name": "a", "radius": 0.1, "static": false},
                                          {"name": "b", "radius": 0.05, "static": false}],
                               "walls": [{"name": "floor", "from": [9990.0, -5.5], "to": [10010.0, -5.5]}],
                               "boxes": [], "surfaces": []})");
  return v;
}

TEST(ReportPlayer, DataDecodesToTheSeriesWithinHalfAQuantum) {
  const ScenarioView v = view_with_geometry();
  static const json box2d_run = json::parse(R"({"engine": "box2d", "contacts": [
      {"a": "a", "b": "floor", "time": 0.5}, {"a": "a", "b": "b", "time": 0.25}, {"a": "nobody", "b": "a", "time": 0.1}]})");
  ScenarioView with_runs = v;
  with_runs.runs.push_back(&box2d_run);
  const PlayerSection p = player_section(with_runs, {"core", "box2d"}, "roundtrip-player");
  ASSERT_EQ(p.frames, 50u);   // as many frames as samples (under the cap): no resampling
  ASSERT_EQ(p.bodies, 2u);

  std::smatch m;
  ASSERT_TRUE(std::regex_search(p.html, m, std::regex("class=player-header>(.*?)</script>")));
  const json header = json::parse(m[1].str());
  ASSERT_TRUE(std::regex_search(p.html, m, std::regex("class=player-data>([A-Za-z0-9+/=]*)</script>")));
  EXPECT_EQ(m[1].str().size(), p.embedded_bytes);
  const std::string bytes = inflate(unbase64(m[1].str()));
  EXPECT_EQ(bytes.size(), p.coded_bytes);
  EXPECT_LT(p.embedded_bytes, p.raw_bytes / 2) << "the coding must save space";

  const double q = header["quantum"].get<double>();
  const double ox = header["origin"][0].get<double>(), oy = header["origin"][1].get<double>();
  EXPECT_GT(q, 0.0);
  EXPECT_LT(q, 20.0 / 4096.0);   // 1/8192 of the scene's extent (the 20 m floor)
  ASSERT_EQ(header["walls"].size(), 1u);
  EXPECT_EQ(header["objects"], json({"a", "b", "floor"}));
  Reader r{bytes};
  for (std::size_t s = 0; s < v.sources.size(); ++s) {
    SCOPED_TRACE(v.sources[s].label);
    const Table& t = v.sources[s].table;
    for (const char* body : {"a", "b"}) {
      const auto& xs = *t.column(std::string("x_") + body);
      const auto& ys = *t.column(std::string("y_") + body);
      std::int64_t qx = 0, qy = 0;
      for (std::size_t k = 0; k < p.frames; ++k) {
        const std::uint64_t cx = r.varint(), cy = r.varint();
        if (!std::isfinite(xs[k])) {
          EXPECT_EQ(cx, 0u) << body << " is gone at sample " << k;
          EXPECT_EQ(cy, 0u);
          continue;
        }
        ASSERT_NE(cx, 0u) << body << " is there at sample " << k;
        qx += unzigzag(cx - 1);
        qy += unzigzag(cy - 1);
        EXPECT_NEAR(ox + static_cast<double>(qx) * q, xs[k], 0.5 * q + 1e-9 * std::abs(xs[k]));
        EXPECT_NEAR(oy + static_cast<double>(qy) * q, ys[k], 0.5 * q + 1e-9);
      }
    }
    const auto& e = *t.column("energy");
    for (std::size_t k = 0; k < p.frames; ++k) EXPECT_NEAR(r.float32(), e[k] - e[0], 1e-6 * std::abs(e[k] - e[0]) + 1e-12);
    const std::uint64_t contacts = r.varint();
    if (s == 0) {
      EXPECT_EQ(contacts, 0u);   // no reference json given
      continue;
    }
    ASSERT_EQ(contacts, 2u);   // the contact naming an unknown object is left out
    const double tick = header["duration"].get<double>() / header["contact_ticks"].get<double>();
    EXPECT_EQ(r.varint(), 0u);   // a
    EXPECT_EQ(r.varint(), 1u);   // b: sorted by time, 0.25 first
    const double t1 = static_cast<double>(r.varint()) * tick;
    EXPECT_NEAR(t1, 0.25, tick);
    EXPECT_EQ(r.varint(), 0u);
    EXPECT_EQ(r.varint(), 2u);   // the floor
    EXPECT_NEAR(t1 + static_cast<double>(r.varint()) * tick, 0.5, 2 * tick);
  }
  EXPECT_EQ(r.at, bytes.size()) << "bytes left over";
}

TEST(ReportPlayer, HeaderCannotCloseItsScriptEarly) {
  ScenarioView v = view_with_geometry();
  v.name = "x</script><b>";
  const PlayerSection p = player_section(v, {"box2d"}, "x");
  EXPECT_EQ(p.html.find("x</script><b>"), std::string::npos);
  EXPECT_NE(p.html.find("x<\\/script>"), std::string::npos);
}

TEST(ReportPlayer, Base64OfKnownBytes) {
  EXPECT_EQ(base64(""), "");
  EXPECT_EQ(base64("f"), "Zg==");
  EXPECT_EQ(base64("fo"), "Zm8=");
  EXPECT_EQ(base64("foo"), "Zm9v");
  EXPECT_EQ(base64("foobar"), "Zm9vYmFy");
}

TEST(ReportFigures, TrajectoriesDrawTheBarriersCutToTheView) {
  const ScenarioView v = view_with_geometry();
  const plot::Figure fig = trajectory_figure(v, {"box2d"});
  ASSERT_EQ(fig.panels.size(), 1u);
  const plot::Panel& p = fig.panels[0];
  const plot::Series* barriers = nullptr;
  for (const plot::Series& s : p.series) {
    if (s.title == "walls, surfaces, boxes") barriers = &s;
  }
  ASSERT_NE(barriers, nullptr);
  ASSERT_EQ(barriers->x.size(), 2u);
  // The floor runs from x = 9990 to 10010, far wider than the paths: cut at the view's edges, at y = -5.5.
  EXPECT_NEAR(barriers->x[0], *p.x.min, 1e-9);
  EXPECT_NEAR(barriers->x[1], *p.x.max, 1e-9);
  EXPECT_NEAR(*p.x.max - *p.x.min, 3.3, 0.5) << "the view follows the paths, not the 20 m floor";
  EXPECT_DOUBLE_EQ(barriers->y[0], -5.5);
  EXPECT_GT(-5.5, *p.y.min) << "a barrier near the paths is inside the view";
}

TEST(ReportFigures, LongSeriesAreEnvelopes) {
  ScenarioView v;
  v.name = "long";
  Source s{"core", "core", {}};
  s.table.names = {"t", "energy"};
  s.table.columns.resize(2);
  for (int k = 0; k < 5000; ++k) {   // 2500 oscillations: aliasing if drawn point by point
    s.table.columns[0].push_back(0.01 * k);
    s.table.columns[1].push_back(1.0 + ((k % 2) ? 1e-3 : -1e-3) * (1.0 + 1e-4 * k));
  }
  v.sources.push_back(s);
  const plot::Figure fig = energy_figure(v, {"core"});
  const plot::Panel& total = fig.panels[0];
  ASSERT_EQ(total.series.size(), 2u);   // upper and lower envelope
  EXPECT_LE(total.series[0].x.size(), 250u);
  for (std::size_t i = 0; i < total.series[0].y.size(); ++i) {
    EXPECT_GT(total.series[0].y[i], 1.0);   // the maxima
    EXPECT_LT(total.series[1].y[i], 1.0);   // the minima
  }
  EXPECT_NE(total.series[0].title.find("min and max"), std::string::npos);
  EXPECT_TRUE(total.series[1].title.empty());
}

}  // namespace
}  // namespace physval::report_detail
