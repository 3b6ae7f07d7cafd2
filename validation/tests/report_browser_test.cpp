// The report page opened in a real browser (headless Chromium, Debian's `chromium`), as a
// user would: its scripts run without error and every scene player draws every frame,
// its bodies and its barriers. Skipped, saying so, only when chromium is not installed.
//
// The page reports on itself (see report_player_script.cpp): with "#selftest" each player
// draws all its frames and sets data-frames-drawn, data-bodies-drawn, data-ink and
// data-barrier-ink; <html> gets data-player-status="ok" once all players started, and
// data-script-errors from a handler installed before any player code.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "physval_command.hpp"

namespace {

namespace fs = std::filesystem;

std::string chromium_path() {
  for (const char* name : {"chromium", "chromium-browser"}) {
    const std::string cmd = std::string("command -v ") + name + " 2>/dev/null";
    FILE* p = ::popen(cmd.c_str(), "r");
    if (p == nullptr) continue;
    char buf[512] = {};
    const bool found = std::fgets(buf, sizeof buf, p) != nullptr;
    ::pclose(p);
    if (found) {
      std::string path = buf;
      while (!path.empty() && (path.back() == '\n' || path.back() == '\r')) path.pop_back();
      if (!path.empty()) return path;
    }
  }
  return "";
}

std::string read_text(const fs::path& file) {
  std::ifstream in(file);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// The page's DOM after its scripts ran (up to `budget_ms` of virtual time).
std::string dump_dom(const std::string& chromium, const fs::path& page, const std::string& hash, const fs::path& work) {
  const fs::path profile = work / "chromium-profile";
  const fs::path out = work / "dom.html", err = work / "chromium.log";
  const std::string cmd = "'" + chromium + "' --headless --no-sandbox --disable-gpu --no-first-run --user-data-dir='" +
                          profile.string() + "' --virtual-time-budget=30000 --dump-dom 'file://" + page.string() + "#" +
                          hash + "' >'" + out.string() + "' 2>'" + err.string() + "'";
  const int rc = std::system(cmd.c_str());
  EXPECT_EQ(rc, 0) << cmd << "\n" << read_text(err);
  return read_text(out);
}

using Attributes = std::map<std::string, std::string>;

Attributes attributes_of(const std::string& tag) {
  Attributes a;
  static const std::regex attr(R"re(([a-z-]+)="([^"]*)")re");
  for (auto it = std::sregex_iterator(tag.begin(), tag.end(), attr); it != std::sregex_iterator(); ++it) {
    a[(*it)[1]] = (*it)[2];
  }
  return a;
}

Attributes html_attributes(const std::string& dom) {
  std::smatch m;
  static const std::regex html_tag(R"re(<html[^>]*>)re");
  return std::regex_search(dom, m, html_tag) ? attributes_of(m.str()) : Attributes{};
}

// Each player's attributes, by scenario.
std::map<std::string, Attributes> players_of(const std::string& dom) {
  std::map<std::string, Attributes> out;
  static const std::regex div(R"re(<div class="player"[^>]*>)re");
  for (auto it = std::sregex_iterator(dom.begin(), dom.end(), div); it != std::sregex_iterator(); ++it) {
    Attributes a = attributes_of(it->str());
    out[a["data-scenario"]] = a;
  }
  return out;
}

long number(const Attributes& a, const std::string& key) {
  const auto it = a.find(key);
  return it == a.end() ? -1 : std::strtol(it->second.c_str(), nullptr, 10);
}

// 300 circles on a grid in a walled box, moving every which way: the player's
// many-body case (the series hold every body, the player draws them all).
void write_gas_300(const fs::path& file) {
  std::ofstream out(file);
  out << "name = \"gas_300\"\ndescription = \"300 elastic circles in a walled box\"\nduration = 1.0\ndt = 0.0166666666666666667\n";
  for (int i = 0; i < 300; ++i) {
    const double x = -0.95 + 0.1 * (i % 20), y = -0.7 + 0.1 * (i / 20);
    out << "\n[[bodies]]\nname = \"g" << i << "\"\nradius = 0.03\nposition = [" << x << ", " << y << "]\nvelocity = ["
        << 0.5 * std::sin(1.3 * i) << ", " << 0.5 * std::cos(0.7 * i) << "]\n";
  }
  const char* walls[][4] = {{"-1.1", "-0.85", "1.1", "-0.85"}, {"1.1", "-0.85", "1.1", "0.85"},
                            {"1.1", "0.85", "-1.1", "0.85"},  {"-1.1", "0.85", "-1.1", "-0.85"}};
  for (int w = 0; w < 4; ++w) {
    out << "\n[[walls]]\nname = \"w" << w << "\"\nfrom = [" << walls[w][0] << ", " << walls[w][1] << "]\nto = ["
        << walls[w][2] << ", " << walls[w][3] << "]\n";
  }
}

class ReportBrowser : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    chromium_ = chromium_path();
    if (chromium_.empty()) return;
    work_ = fs::temp_directory_path() / ("physval-report-browser-" + std::to_string(::getpid()));
    fs::remove_all(work_);
    fs::create_directories(work_);
    write_gas_300(work_ / "gas_300.toml");
    const std::string scenarios = PHYSVAL_SOURCE_SCENARIOS;
    std::string args = "run";
    for (const char* s : {"/models/circle_gas.toml", "/hard/tunnelling_thin_wall.toml", "/models/pinball_surface.toml",
                          "/basics/free_fall_floor.toml", "/models/particles_explosion.toml",
                          "/models/box_obstacle.toml", "/basics/equal_mass_swap.toml",
                          "/hard/pi_billiard_1e8.toml"}) {   // 31,000 contacts of one pair in 2 s
      args.append(" ").append(scenarios).append(s);
    }
    args.append(" ").append((work_ / "gas_300.toml").string());
    args.append(" --out ").append((work_ / "out").string()).append(" --report --quiet -j 2");
    run_ = physval_test::physval(args);
  }
  static void TearDownTestSuite() {
    if (!work_.empty()) fs::remove_all(work_);
  }
  void SetUp() override {
    if (chromium_.empty()) {
      GTEST_SKIP() << "chromium is not installed (Debian package `chromium`, installed by scripts/setup.sh): "
                      "the report's scene player was NOT checked in a browser";
    }
    ASSERT_EQ(run_.status, 0) << run_.output;
    ASSERT_TRUE(fs::exists(work_ / "out" / "report.html")) << run_.output;
  }
  static fs::path page() { return work_ / "out" / "report.html"; }

  static inline std::string chromium_;
  static inline fs::path work_;
  static inline physval_test::Result run_;
};

TEST_F(ReportBrowser, EveryPlayerDrawsEveryFrameWithoutScriptErrors) {
  const std::string dom = dump_dom(chromium_, page(), "selftest", work_);
  Attributes html = html_attributes(dom);
  EXPECT_EQ(html.count("data-script-errors"), 0u) << html["data-script-errors"];
  EXPECT_EQ(html["data-player-status"], "ok");
  EXPECT_EQ(html["data-players"], "9");
  const auto players = players_of(dom);
  ASSERT_EQ(players.size(), 9u) << dom.substr(0, 2000);
  // What each scene holds at t = 0 (the frame drawn last): its bodies, and whether it has barriers.
  const std::map<std::string, std::pair<long, bool>> expected = {
      {"circle_gas", {200, true}},     {"tunnelling_thin_wall", {1, true}}, {"pinball_surface", {1, true}},
      {"free_fall_floor", {1, true}},  {"box_obstacle", {1, true}},          {"equal_mass_swap", {2, false}},
      {"gas_300", {300, true}},        {"pi_billiard_1e8", {2, true}}};
  for (const auto& [name, a] : players) {
    SCOPED_TRACE(name);
    EXPECT_GT(number(a, "data-frames-drawn"), 2) << "the selftest draws every frame";
    EXPECT_GT(number(a, "data-ink"), 200) << "the canvas stayed blank";
    const auto it = expected.find(name);
    if (it == expected.end()) continue;
    EXPECT_EQ(number(a, "data-bodies-drawn"), it->second.first);
    if (it->second.second) {
      EXPECT_GT(number(a, "data-barrier-ink"), 100) << "walls, surfaces or boxes not drawn";
    } else {
      EXPECT_EQ(number(a, "data-barrier-ink"), 0) << "dark pixels where the scene has no barrier";
    }
  }
}

// The checks above can fail: a page whose player data is damaged, or whose script does
// not parse, reports the error (and no "ok") where the test looks.
TEST_F(ReportBrowser, ScriptErrorsAreCaught) {
  const std::string good = read_text(page());
  {
    std::string damaged = good;
    const std::string mark = "class=player-data>";
    const std::size_t at = damaged.find(mark);
    ASSERT_NE(at, std::string::npos);
    damaged.insert(at + mark.size(), "!!not64!");   // not base64: atob throws
    const fs::path file = work_ / "out" / "damaged_data.html";
    std::ofstream(file) << damaged;
    Attributes html = html_attributes(dump_dom(chromium_, file, "selftest", work_));
    EXPECT_NE(html["data-script-errors"], "");
    EXPECT_EQ(html["data-player-status"], "failed");
  }
  {
    std::string damaged = good;
    const std::string mark = "class Player {";
    const std::size_t at = damaged.find(mark);
    ASSERT_NE(at, std::string::npos);
    damaged.insert(at, "}}(");
    const fs::path file = work_ / "out" / "damaged_script.html";
    std::ofstream(file) << damaged;
    Attributes html = html_attributes(dump_dom(chromium_, file, "selftest", work_));
    EXPECT_NE(html["data-script-errors"].find("SyntaxError"), std::string::npos) << html["data-script-errors"];
    EXPECT_EQ(html.count("data-player-status"), 0u);
  }
}

}  // namespace
