// `--shard I/N` and `physval merge`: the split is deterministic and balanced; a suite run
// in three shards and merged gives the results.json (timings aside), JUnit file, series
// and exit status of one run, a failing gate included; a sweep in two shards merges to
// the points and orders of one sweep; merge refuses parts of different jobs (exit 2).
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numeric>
#include <regex>

#include <nlohmann/json.hpp>

#include "physval/validation/shard.hpp"
#include "physval_command.hpp"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using physval_test::physval;

std::string read(const fs::path& f) {
  std::ifstream in(f);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void write(const fs::path& f, const std::string& text) {
  fs::create_directories(f.parent_path());
  std::ofstream(f) << text;
}

// results.json without what depends on the clock or the machine.
json without_timings(json j) {
  if (j.is_object()) {
    for (const char* key : {"wall_seconds", "load_seconds", "context"}) j.erase(key);
    for (auto& [k, v] : j.items()) v = without_timings(v);
  } else if (j.is_array()) {
    for (auto& v : j) v = without_timings(v);
  }
  return j;
}

std::string junit_without_times(const std::string& xml) {
  return std::regex_replace(xml, std::regex(R"(( time| timestamp)="[^"]*")"), "");
}

TEST(ShardSplit, ParsesIOverN) {
  std::string error;
  auto s = physval::parse_shard("2/5", error);
  ASSERT_TRUE(s);
  EXPECT_EQ(s->index, 2u);
  EXPECT_EQ(s->count, 5u);
  for (const char* bad : {"5/5", "1/0", "-1/3", "1", "a/3", "1/3x", "", "/3", "1/"}) {
    EXPECT_FALSE(physval::parse_shard(bad, error)) << bad;
    EXPECT_NE(error.find("--shard"), std::string::npos);
  }
}

TEST(ShardSplit, EveryItemInOneShardBalancedAndDeterministic) {
  std::vector<double> costs;
  for (int i = 0; i < 97; ++i) costs.push_back(static_cast<double>((i * 37) % 101 + 1));
  for (std::size_t n : {1u, 2u, 3u, 7u, 200u}) {
    const auto a = physval::assign_shards(costs, n);
    EXPECT_EQ(a, physval::assign_shards(costs, n));
    ASSERT_EQ(a.size(), costs.size());
    std::vector<double> load(n, 0.0);
    for (std::size_t i = 0; i < a.size(); ++i) {
      ASSERT_LT(a[i], n);
      load[a[i]] += costs[i];
    }
    // Longest-processing-time: no shard exceeds the lightest by more than the largest item.
    const double biggest = *std::max_element(costs.begin(), costs.end());
    EXPECT_LE(*std::max_element(load.begin(), load.end()) - *std::min_element(load.begin(), load.end()), biggest) << n;
    EXPECT_DOUBLE_EQ(std::accumulate(load.begin(), load.end(), 0.0), std::accumulate(costs.begin(), costs.end(), 0.0));
  }
  // One huge item: it gets a shard of its own.
  const auto b = physval::assign_shards({100, 1, 1, 1, 1}, 2);
  for (std::size_t i = 1; i < b.size(); ++i) EXPECT_NE(b[i], b[0]);
}

class ShardMerge : public ::testing::Test {
 protected:
  fs::path root;
  fs::path suite;
  std::string common;

  void SetUp() override {
    root = fs::temp_directory_path() / ("physval-shard-merge-" + std::to_string(::getpid()) + "-" +
                                        ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root);
    suite = root / "suite";
    for (const char* f : {"basics/head_on_elastic.toml", "basics/equal_mass_swap.toml", "basics/free_fall_floor.toml",
                          "models/projectile.toml", "models/drag_wind.toml", "models/box_obstacle.toml",
                          // bullet's tunnelling: a divergence its gate accepts (known_divergence)
                          "hard/tunnelling_thin_wall_offgrid.toml"}) {
      fs::create_directories(suite / fs::path(f).parent_path());
      fs::copy_file(fs::path(PHYSVAL_SOURCE_SCENARIOS) / f, suite / f);
    }
    // A gate no engine but an exact one meets: gate fails on box2d and bullet.
    write(suite / "failing_gate.toml",
          "name = \"failing_gate\"\nduration = 1.0\ndt = 0.01\n"
          "[[bodies]]\nname = \"a\"\nradius = 0.1\nmass = 1\nposition = [0, 0]\nvelocity = [1, 0]\n"
          "[[bodies]]\nname = \"b\"\nradius = 0.1\nmass = 2\nposition = [0.6, 0]\n"
          "[gate]\nposition_divergence = 1e-300\n");
    common = " " + suite.string() + " --quiet -j 2 --no-cache";
  }
  void TearDown() override { fs::remove_all(root); }

  std::string dir(const std::string& name) const { return (root / name).string(); }
};

TEST_F(ShardMerge, ThreeShardsMergeToTheSingleRun) {
  const auto single = physval("gate" + common + " --out " + dir("single") + " --junit " + dir("single.xml"));
  ASSERT_EQ(single.status, 1) << single.output;   // failing_gate fails
  std::vector<int> statuses;
  std::string shards;
  for (int i = 0; i < 3; ++i) {
    const auto r = physval("gate" + common + " --shard " + std::to_string(i) + "/3 --out " + dir("s" + std::to_string(i)));
    ASSERT_NE(r.status, 2) << r.output;
    statuses.push_back(r.status);
    shards += " " + dir("s" + std::to_string(i));
  }
  EXPECT_EQ(std::count(statuses.begin(), statuses.end(), 1), 1);   // only the shard with failing_gate fails
  // Each scenario ran in exactly one shard.
  std::size_t runs = 0;
  for (int i = 0; i < 3; ++i) runs += json::parse(read(root / ("s" + std::to_string(i)) / "results.json"))["runs"].size();
  const json one = json::parse(read(root / "single" / "results.json"));
  EXPECT_EQ(runs, one["runs"].size());

  const auto merged = physval("merge" + shards + " --out " + dir("merged") + " --junit " + dir("merged.xml"));
  EXPECT_EQ(merged.status, single.status) << merged.output;
  const json all = json::parse(read(root / "merged" / "results.json"));
  EXPECT_FALSE(all.contains("shard"));
  EXPECT_EQ(without_timings(all), without_timings(one));
  EXPECT_EQ(junit_without_times(read(root / "merged.xml")), junit_without_times(read(root / "single.xml")));
  for (const auto& e : fs::recursive_directory_iterator(root / "single" / "series")) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), root / "single");
    EXPECT_EQ(read(root / "merged" / rel), read(e.path())) << rel;
  }
  // The shards in another order merge to the same.
  const auto reversed = physval("merge " + dir("s2") + " " + dir("s0") + " " + dir("s1") + " --out " + dir("merged2"));
  EXPECT_EQ(reversed.status, single.status);
  EXPECT_EQ(read(root / "merged2" / "results.json"), read(root / "merged" / "results.json"));

  // Without the failing scenario every part passes, and so does the merge.
  fs::remove(suite / "failing_gate.toml");
  for (int i = 0; i < 2; ++i) {
    ASSERT_EQ(physval("gate" + common + " --shard " + std::to_string(i) + "/2 --out " + dir("p" + std::to_string(i))).status, 0);
  }
  EXPECT_EQ(physval("merge " + dir("p0") + " " + dir("p1") + " --out " + dir("pm")).status, 0);
}

TEST_F(ShardMerge, RefusesPartsOfDifferentJobs) {
  for (int i = 0; i < 3; ++i) {
    ASSERT_NE(physval("gate" + common + " --engines core --shard " + std::to_string(i) + "/3 --out " + dir("s" + std::to_string(i))).status, 2);
  }
  const std::string s0 = " " + dir("s0"), s1 = " " + dir("s1"), s2 = " " + dir("s2");
  auto refused = [&](const std::string& args, const std::string& why) {
    const auto r = physval("merge" + args + " --out " + dir("m"));
    EXPECT_EQ(r.status, 2) << args << "\n" << r.output;
    EXPECT_NE(r.output.find(why), std::string::npos) << "expected \"" << why << "\" in:\n" << r.output;
    EXPECT_FALSE(fs::exists(root / "m")) << args;
  };
  refused(s0 + s1, "missing shard(s) 2 of 3");
  refused(s0 + s1 + s1 + s2, "given twice");
  ASSERT_EQ(physval("gate" + common + " --engines core --out " + dir("whole")).status, 1);
  refused(s0 + s1 + " " + dir("whole"), "not a shard's output");
  // Another N, other options, another command, another scenario text, another version.
  ASSERT_NE(physval("gate" + common + " --engines core --shard 1/2 --out " + dir("n2")).status, 2);
  refused(s0 + s1 + " " + dir("n2"), "share N");
  ASSERT_NE(physval("gate" + common + " --engines core --dt 1/200 --shard 2/3 --out " + dir("dt")).status, 2);
  refused(s0 + s1 + " " + dir("dt"), "different options");
  ASSERT_NE(physval("run" + common + " --engines core --shard 2/3 --out " + dir("run")).status, 2);
  refused(s0 + s1 + " " + dir("run"), "different command");
  fs::copy(root / "s2", root / "old", fs::copy_options::recursive);
  json doc = json::parse(read(root / "old" / "results.json"));
  doc["physval_version"] = "0.0.1";
  write(root / "old" / "results.json", doc.dump());
  refused(s0 + s1 + " " + dir("old"), "physval version");
  // A shard whose results.json lost a run (edited by hand, cut short) merged one engine
  // short, exit 0 when what remained passed.
  fs::copy(root / "s2", root / "cut", fs::copy_options::recursive);
  doc = json::parse(read(root / "cut" / "results.json"));
  ASSERT_FALSE(doc["runs"].empty());
  const std::string lost = doc["runs"].back()["scenario"].get<std::string>();
  doc["runs"].erase(doc["runs"].size() - 1);
  write(root / "cut" / "results.json", doc.dump());
  refused(s0 + s1 + " " + dir("cut"), "scenario " + lost + " has no run of core");
  write(suite / "basics" / "head_on_elastic.toml", read(suite / "basics" / "head_on_elastic.toml") + "\n# edited\n");
  ASSERT_NE(physval("gate" + common + " --engines core --shard 2/3 --out " + dir("edited")).status, 2);
  refused(s0 + s1 + " " + dir("edited"), "different scenario set");
  refused(s0 + s1 + " " + dir("nowhere"), "no such folder");
  // The right three still merge.
  EXPECT_EQ(physval("merge" + s0 + s1 + s2 + " --out " + dir("m")).status, 1);
}

TEST_F(ShardMerge, ShardOptionErrorsAreUsageErrors) {
  for (const char* bad : {"3/3", "1", "x/2"}) {
    const auto r = physval("run" + common + " --shard " + bad + " --out " + dir("bad"));
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_NE(r.output.find("--shard"), std::string::npos) << r.output;
  }
}

TEST_F(ShardMerge, SweepShardsMergeToTheSingleSweep) {
  const std::string scene = (suite / "basics" / "head_on_elastic.toml").string();
  const std::string args = "sweep " + scene + " --dt 1/100,1/200,1/400 --repetitions 1 --quiet --no-cache -j 2";
  ASSERT_EQ(physval(args + " --out " + dir("single")).status, 0);
  ASSERT_EQ(physval(args + " --shard 0/2 --out " + dir("w0")).status, 0);
  ASSERT_EQ(physval(args + " --shard 1/2 --out " + dir("w1")).status, 0);
  const auto merged = physval("merge " + dir("w1") + " " + dir("w0") + " --out " + dir("merged"));
  ASSERT_EQ(merged.status, 0) << merged.output;
  const json a = json::parse(read(root / "single" / "sweep.json"));
  const json b = json::parse(read(root / "merged" / "sweep.json"));
  const json p0 = json::parse(read(root / "w0" / "sweep.json"))["points"];
  const json p1 = json::parse(read(root / "w1" / "sweep.json"))["points"];
  EXPECT_FALSE(p0.empty());
  EXPECT_FALSE(p1.empty());
  EXPECT_EQ(p0.size() + p1.size(), a["points"].size());
  auto untimed = [](json points) {
    for (json& p : points) {
      for (const char* k : {"wall_per_sim_median", "wall_per_sim_min", "wall_per_sim_max", "spread", "spread_warning",
                            "pareto", "runs"}) {
        p.erase(k);
      }
    }
    return points;
  };
  EXPECT_EQ(untimed(b["points"]), untimed(a["points"]));
  EXPECT_EQ(b["orders"], a["orders"]);
  EXPECT_EQ(b["reference"], a["reference"]);
  EXPECT_FALSE(b.contains("shard"));
  // A sweep's shards and a suite's do not mix; a sweep shard alone is incomplete.
  EXPECT_EQ(physval("merge " + dir("w0") + " --out " + dir("m1")).status, 2);
}

}  // namespace
