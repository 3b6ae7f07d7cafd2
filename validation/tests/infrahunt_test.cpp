// The infrastructure hunt: ways to make physval green when something went wrong outside
// the physics (merge, shards, the reference cache, the baseline). Each test failed before
// its fix (README, "The infrastructure hunt").
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <iterator>

#include <nlohmann/json.hpp>

#include "physval/adapters/registry.hpp"
#include "physval/validation/comparator.hpp"
#include "physval/validation/reference_cache.hpp"
#include "physval/validation/runner.hpp"
#include "physval/validation/run_record_io.hpp"
#include "physval/validation/scenario_loader.hpp"
#include "physval_command.hpp"

namespace physval {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using physval_test::physval;

std::string read(const fs::path& f) {
  std::ifstream in(f, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void put(const fs::path& f, const std::string& text) {
  fs::create_directories(f.parent_path());
  std::ofstream(f, std::ios::binary) << text;
}

// Two balls on a line, b at rest 1 m to the right of a; `velocity` is a's (negative: away
// from b, which then stays where it is, as the expectation says).
std::string pair_scene(const std::string& name, const std::string& velocity, const std::string& tail = "") {
  return "name = \"" + name + "\"\nduration = 1.0\ndt = 0.01\n"
         "[[bodies]]\nname = \"a\"\nradius = 0.1\nmass = 1\nposition = [0, 0]\nvelocity = [" + velocity + ", 0]\n"
         "[[bodies]]\nname = \"b\"\nradius = 0.1\nmass = 2\nposition = [1, 0]\n"
         "[expect]\nfinal = [ { body = \"b\", position = [1.0, 0.0] } ]\n" + tail;
}

class InfraHunt : public physval_test::TempDirTest {
 protected:
  InfraHunt() : TempDirTest("physval-infrahunt-") {}
  std::string dir(const std::string& name) const { return (dir_ / name).string(); }
};

// --- merge: shards of another build -------------------------------------------------

// A shard folder written by another physval executable (a folder left from an earlier
// build whose task died this time, a node with an older install) merged: the version
// number is the same across rebuilds, and merge compared nothing else of the build. And
// a shard folder without its series merged, into a folder lacking them.
TEST_F(InfraHunt, MergeRefusesAShardWrittenByAnotherPhysvalExecutable) {
  put(dir_ / "suite" / "one.toml", pair_scene("one", "-1"));
  put(dir_ / "suite" / "two.toml", pair_scene("two", "-2"));
  const std::string common = " " + dir("suite") + " --engines core --quiet -j 1 --no-cache";
  // The same program, other bytes: the copy runs exactly as the original.
  const fs::path other = dir_ / "physval-other";
  fs::copy_file(PHYSVAL_EXE, other);
  { std::ofstream(other, std::ios::binary | std::ios::app) << "rebuilt"; }
  fs::permissions(other, fs::perms::owner_all);
  const auto s0 = physval("gate" + common + " --shard 0/2 --out " + dir("s0"));
  ASSERT_NE(s0.status, 2) << s0.output;
  const std::string cmd = other.string() + " gate" + common + " --shard 1/2 --out " + dir("s1") + " > /dev/null 2>&1";
  const int w = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(w) && WEXITSTATUS(w) != 2);
  const auto merged = physval("merge " + dir("s0") + " " + dir("s1") + " --out " + dir("m"));
  EXPECT_EQ(merged.status, 2) << merged.output;
  EXPECT_NE(merged.output.find("another physval executable"), std::string::npos) << merged.output;
  EXPECT_FALSE(fs::exists(dir_ / "m"));
  // Both shards from one executable still merge, to the single run's status.
  ASSERT_NE(physval("gate" + common + " --shard 1/2 --out " + dir("s1b")).status, 2);
  EXPECT_EQ(physval("merge " + dir("s0") + " " + dir("s1b") + " --out " + dir("m")).status, 0);
  // A shard folder copied in part (its series missing) is not a whole shard output.
  fs::copy(dir_ / "s1b", dir_ / "s1c", fs::copy_options::recursive);
  fs::remove_all(dir_ / "s1c" / "series");
  const auto partial = physval("merge " + dir("s0") + " " + dir("s1c") + " --out " + dir("m2"));
  EXPECT_EQ(partial.status, 2) << partial.output;
  EXPECT_NE(partial.output.find("are missing"), std::string::npos) << partial.output;
  EXPECT_FALSE(fs::exists(dir_ / "m2"));
  const json shard = json::parse(read(dir_ / "s0" / "results.json"))["shard"];
  ASSERT_TRUE(shard.contains("build"));
  EXPECT_EQ(shard["build"]["engines"][0]["name"], "core");
}

// --- the reference cache ---------------------------------------------------------------

class InfraHuntCache : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("physval-infrahunt-cache-" + std::to_string(::getpid()) + "-" +
                                         ::testing::UnitTest::GetInstance()->current_test_info()->name());
    fs::remove_all(root_);
    fs::create_directories(root_);
    options_.reference_cache = (root_ / "cache").string();
  }
  void TearDown() override { fs::remove_all(root_); }
  Scene load(const fs::path& file) {
    ScenarioLoad l = load_scenario_file(file);
    if (!l.scene) throw std::runtime_error("test scene does not load");
    return *l.scene;
  }
  fs::path entry() const {
    if (!fs::is_directory(root_ / "cache")) return {};
    for (const auto& e : fs::directory_iterator(root_ / "cache")) {
      if (e.path().extension() == ".ref") return e.path();
    }
    return {};
  }
  fs::path root_;
  RunOptions options_;
};

std::vector<std::uint8_t> run_bytes(const Reference& r) { return r.run ? encode_run_record(*r.run) : std::vector<std::uint8_t>{}; }

// A byte changed inside a cache entry (a damaged disk, a file overwritten in part) still
// decoded when it fell inside the run's series: the key matched, and the scenario was
// compared with a reference nobody computed. Every entry now carries a hash of its bytes.
TEST_F(InfraHuntCache, AnEntryDamagedAnywhereIsRecomputedNeverServed) {
  const fs::path file = root_ / "pair.toml";
  put(file, pair_scene("pair", "2"));
  const Scene scene = load(file);
  const CachedReference first = cached_reference(scene, options_);
  ASSERT_TRUE(first.reference.available) << first.reference.reason;
  const std::vector<std::uint8_t> truth = run_bytes(first.reference);
  const fs::path e = entry();
  ASSERT_FALSE(e.empty());
  const std::string good = read(e);
  ASSERT_GT(good.size(), 1000u);
  int served_wrong = 0, positions = 0;
  for (std::size_t at = 3; at < good.size(); at += good.size() / 97 + 1) {
    std::string bad = good;
    bad[at] = static_cast<char>(bad[at] ^ 0x10);
    put(e, bad);
    const CachedReference again = cached_reference(scene, options_);
    ++positions;
    if (again.from_cache && (run_bytes(again.reference) != truth || again.reference.dt != first.reference.dt ||
                             again.reference.convergence_error != first.reference.convergence_error)) {
      ++served_wrong;
    }
    if (again.from_cache) {
      EXPECT_EQ(run_bytes(again.reference), truth) << "byte " << at;
    }
  }
  EXPECT_GT(positions, 90);
  EXPECT_EQ(served_wrong, 0);
  // A truncated entry likewise.
  put(e, good.substr(0, good.size() / 2));
  EXPECT_FALSE(cached_reference(scene, options_).from_cache);
  // And the whole entry is read back.
  put(e, good);
  EXPECT_TRUE(cached_reference(scene, options_).from_cache);
}

// A scenario file edited while physval ran (between loading it and keying its reference)
// had the reference of the scene as loaded stored under the *edited* text: the next run
// of the edited file read it back, and was compared with another scene's reference.
TEST_F(InfraHuntCache, AFileEditedDuringTheRunNeitherStoresNorServesAStaleReference) {
  const fs::path file = root_ / "pair.toml";
  put(file, pair_scene("pair", "2"));
  const Scene loaded = load(file);
  put(file, pair_scene("pair", "-3"));   // edited after loading, before the reference
  const CachedReference during = cached_reference(loaded, options_);
  ASSERT_TRUE(during.reference.available);
  EXPECT_FALSE(during.from_cache);
  EXPECT_TRUE(entry().empty()) << "a reference stored under text it was not computed from";
  // The next run, of the file as it is now, computes its own reference.
  const Scene edited = load(file);
  const CachedReference next = cached_reference(edited, options_);
  EXPECT_FALSE(next.from_cache);
  ASSERT_TRUE(next.reference.run && during.reference.run);
  const double x_next = next.reference.run->final_states.at(0).position.x;
  const double x_during = during.reference.run->final_states.at(0).position.x;
  EXPECT_NEAR(x_next, -3.0, 1e-9);   // a at -3 m/s meets nothing: x = -3 t
  EXPECT_GT(x_during, -0.5);         // a at 2 m/s towards b
  EXPECT_TRUE(cached_reference(edited, options_).from_cache);   // and is cached as usual
}

// --- the baseline: an engine it ran is gone ----------------------------------------

// A baseline run on an engine that this physval no longer has (a CI artifact without the
// bundled plugins, a --plugin dropped from the command) or that the scenario's engines
// list now leaves out simply vanished: fewer runs, all passing, exit 0.
TEST_F(InfraHunt, ABaselineRunOfAnEngineNoLongerRunFailsTheGate) {
  put(dir_ / "suite" / "one.toml", pair_scene("one", "-1"));
  const std::string common = " " + dir("suite") + " --quiet -j 1 --no-cache";
  ASSERT_EQ(physval("gate" + common + " --engines core,box2d --out " + dir("base")).status, 0);
  // The baseline as a physval with a plugin engine "retired" (since removed) wrote it.
  json base = json::parse(read(dir_ / "base" / "results.json"));
  json plugin_run = base["runs"][0];
  ASSERT_EQ(plugin_run["engine"], "core");
  plugin_run["engine"] = "retired";
  base["runs"].push_back(plugin_run);
  put(dir_ / "base" / "results.json", base.dump(2));
  const auto gone = physval("gate" + common + " --engines core,box2d --baseline " + dir("base") + "/results.json --out " +
                            dir("o1") + " --junit " + dir("o1.xml"));
  // --engines names what is wanted; "retired" is not among them: left out on purpose.
  EXPECT_EQ(gone.status, 0) << gone.output;
  const auto all = physval("gate" + common + " --baseline " + dir("base") + "/results.json --out " + dir("o2") +
                           " --junit " + dir("o2.xml"));
  EXPECT_EQ(all.status, 1) << all.output;
  const std::string xml = read(dir_ / "o2.xml");
  EXPECT_NE(xml.find("name=\"retired\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("no engine named retired is loaded"), std::string::npos) << xml;
  // The scenario's own engines list leaving box2d out fails too.
  put(dir_ / "suite" / "one.toml", "engines = [\"core\"]\n" + pair_scene("one", "-1"));
  const auto narrowed = physval("gate" + common + " --engines core,box2d --baseline " + dir("base") + "/results.json --out " +
                                dir("o3"));
  EXPECT_EQ(narrowed.status, 1) << narrowed.output;
  EXPECT_NE(narrowed.output.find("not run now"), std::string::npos) << narrowed.output;
}

// --- sweep: nothing measured -------------------------------------------------------

// A sweep whose every point diverged (or crashed) printed a table of statuses, wrote its
// files and exited 0, as a sweep that measured its figures does; merged shards likewise.
TEST_F(InfraHunt, ASweepWhosePointsAllDivergedExitsOne) {
  // The energy of 1e300 kg at 1e10 m/s is not finite: every engine diverges at once.
  put(dir_ / "inf.toml", "name = \"inf\"\nduration = 0.1\ndt = 0.01\n[[bodies]]\nname = \"a\"\nradius = 0.1\n"
                         "mass = 1e300\nposition = [0, 0]\nvelocity = [1e10, 0]\n");
  const std::string common = " " + dir("inf.toml") + " --engines core,box2d --dt 1/100,1/200 --no-cache -j 1 --quiet";
  const auto one = physval("sweep" + common + " --out " + dir("sw"));
  EXPECT_EQ(one.status, 1) << one.output;
  EXPECT_NE(one.output.find("sweep measured nothing: every point diverged or failed"), std::string::npos) << one.output;
  EXPECT_TRUE(fs::exists(dir_ / "sw" / "sweep.json"));   // the statuses are still written
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(physval("sweep" + common + " --shard " + std::to_string(i) + "/2 --out " + dir("s" + std::to_string(i))).status, 0);
  }
  EXPECT_EQ(physval("merge " + dir("s0") + " " + dir("s1") + " --out " + dir("m")).status, 1);
  // A sweep with points that ran is still a success.
  put(dir_ / "fine.toml", pair_scene("fine", "-1"));
  EXPECT_EQ(physval("sweep " + dir("fine.toml") + " --engines core --dt 1/100,1/200 --no-cache -j 1 --quiet --repetitions 1 --out " +
                    dir("ok")).status, 0);
}

// A sweep whose every point missed the scenario's [expect] (hunt6) wrote "ok" and an error
// figure for each point and exited 0, where `run` of the same scene exits 1. Now each point
// lists the checks it failed, and an engine right at no step size and no setting makes the
// sweep (and the merge of its shards) exit 1; one right somewhere is a finding, not a failure.
TEST_F(InfraHunt, ASweepWhoseEngineMissesTheExpectationAtEveryStepSizeExitsOne) {
  const std::string fall = "duration = 1.0\ndt = 0.01\n[world]\ngravity = [0.0, -9.81]\n[[bodies]]\nname = \"a\"\n"
                           "radius = 0.1\nposition = [0.0, 10.0]\n[expect]\nfinal = [ { body = \"a\", velocity = [0.0, ";
  put(dir_ / "wrong.toml", "name = \"wrong\"\n" + fall + "-9.0], tolerance = 1e-3 } ]\n");   // v = -g t = -9.81
  put(dir_ / "right.toml", "name = \"right\"\n" + fall + "-9.81], tolerance = 1e-3 } ]\n");
  const std::string opts = " --engines core,box2d --dt 1/100,1/200 --no-cache -j 1 --quiet --repetitions 1";
  ASSERT_EQ(physval("run " + dir("wrong.toml") + " --engines core,box2d --no-cache -j 1 --quiet --out " + dir("r")).status, 1);
  const auto one = physval("sweep " + dir("wrong.toml") + opts + " --out " + dir("sw"));
  EXPECT_EQ(one.status, 1) << one.output;
  EXPECT_NE(one.output.find("an engine was right at no step size: core: none of its"), std::string::npos) << one.output;
  EXPECT_NE(one.output.find("box2d: none of its"), std::string::npos) << one.output;
  EXPECT_NE(one.output.find("missed 2 checks (expect.final.a.velocity"), std::string::npos) << one.output;
  const nlohmann::json sweep = nlohmann::json::parse(std::ifstream(dir_ / "sw" / "sweep.json"));
  for (const auto& p : sweep.at("points")) {
    EXPECT_EQ(p.at("status"), "ok");
    EXPECT_EQ(p.at("checks_failed").at(0), "expect.final.a.velocity");
  }
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(physval("sweep " + dir("wrong.toml") + opts + " --shard " + std::to_string(i) + "/2 --out " + dir("s" + std::to_string(i))).status, 0);
  }
  const auto merged = physval("merge " + dir("s0") + " " + dir("s1") + " --out " + dir("m"));
  EXPECT_EQ(merged.status, 1) << merged.output;
  EXPECT_NE(merged.output.find("an engine was right at no step size"), std::string::npos) << merged.output;
  // The right expectation: every point holds it, exit 0, nothing listed.
  const auto fine = physval("sweep " + dir("right.toml") + opts + " --out " + dir("ok"));
  EXPECT_EQ(fine.status, 0) << fine.output;
  EXPECT_EQ(fine.output.find("missed"), std::string::npos) << fine.output;
}

// --- JUnit: the last run's file ---------------------------------------------------------

// A gate that stopped before writing its JUnit file (bad input, killed by a CI timeout)
// left the previous run's file in place: a CI step that publishes it read the earlier
// verdict (all passed) as this run's.
TEST_F(InfraHunt, AGateThatWritesNoJunitLeavesNoEarlierJunit) {
  put(dir_ / "suite" / "one.toml", pair_scene("one", "-1"));
  const std::string junit = dir("junit.xml");
  ASSERT_EQ(physval("gate " + dir("suite") + " --engines core --no-cache -j 1 --quiet --out " + dir("o") + " --junit " + junit).status, 0);
  ASSERT_TRUE(fs::exists(junit));
  // Bad input now (a typo in the file): exit 2, nothing run, and no JUnit file.
  put(dir_ / "suite" / "one.toml", pair_scene("one", "-1") + "[gaet]\n");
  EXPECT_EQ(physval("gate " + dir("suite") + " --engines core --no-cache -j 1 --quiet --out " + dir("o") + " --junit " + junit).status, 2);
  EXPECT_FALSE(fs::exists(junit)) << "the earlier run's JUnit file is still there";
  // Killed mid-run (SIGKILL, as a CI timeout or the OOM killer does): no JUnit file either.
  put(dir_ / "suite" / "one.toml", pair_scene("one", "-1"));
  ASSERT_EQ(physval("gate " + dir("suite") + " --engines core --no-cache -j 1 --quiet --out " + dir("o") + " --junit " + junit).status, 0);
  put(dir_ / "suite" / "slow.toml", "name = \"slow\"\nduration = 1000.0\ndt = 1e-5\n[[bodies]]\nname = \"a\"\nradius = 0.1\n"
                                    "mass = 1\nposition = [0, 0]\nvelocity = [1, 0]\n[gate]\nenergy_drift = 1\n");
  const std::string cmd = "timeout -s KILL 1 " + std::string(PHYSVAL_EXE) + " gate " + dir("suite") +
                          " --engines core --no-cache -j 1 --quiet --out " + dir("o") + " --junit " + junit + " > /dev/null 2>&1";
  const int w = std::system(cmd.c_str());
  ASSERT_TRUE(WIFEXITED(w) && WEXITSTATUS(w) == 137) << w;   // killed, as intended
  EXPECT_FALSE(fs::exists(junit)) << "the earlier run's JUnit file survived a killed run";
  // A refused merge leaves none either.
  put(junit, "<testsuites/>\n");
  EXPECT_EQ(physval("merge " + dir("o") + " --out " + dir("m") + " --junit " + junit).status, 2);
  EXPECT_FALSE(fs::exists(junit));
}

// --- an engine that misreports the scene's bodies ---------------------------------------

// core, with the scene's bodies reported through `lie` (a plugin's body_meta is its own
// word): its motion is core's, only what it says about the bodies differs.
class MisreportingEngine : public Engine {
 public:
  explicit MisreportingEngine(std::function<void(BodyMeta&)> lie) : inner_(find_engine("core")->create()), lie_(std::move(lie)) {}
  const EngineInfo& info() const override { return inner_->info(); }
  void load(const Scene& scene) override { inner_->load(scene); }
  void step(double dt) override {
    inner_->step(dt);
    slowed_ *= 0.99;   // and it loses energy: every body's reported speed drops 1% a step
  }
  double time() const override { return inner_->time(); }
  std::size_t body_count() const override { return inner_->body_count(); }
  BodyMeta body_meta(std::size_t i) const override {
    BodyMeta m = inner_->body_meta(i);
    lie_(m);
    return m;
  }
  void read_states(std::vector<BodyState>& out) const override {
    inner_->read_states(out);
    for (BodyState& b : out) b.velocity = slowed_ * b.velocity;
  }
  const std::vector<ContactEvent>& contacts() const override { return inner_->contacts(); }
  std::vector<Setting> settings() const override { return inner_->settings(); }

 private:
  std::unique_ptr<Engine> inner_;
  std::function<void(BodyMeta&)> lie_;
  double slowed_ = 1.0;
};

// An engine that reported its bodies massless (or static) had an energy and momentum of 0
// at every sample: energy_drift and linear_momentum_drift read 0 whatever it did, and a
// gate on them passed an engine that lost 63% of its speed.
TEST_F(InfraHunt, AnEngineThatMisreportsTheScenesBodiesIsAnError) {
  put(dir_ / "free.toml", "name = \"free\"\nduration = 1.0\ndt = 0.01\n[[bodies]]\nname = \"a\"\nradius = 0.1\nmass = 2\n"
                          "position = [0, 0]\nvelocity = [1, 0]\n[gate]\nenergy_drift = 1e-9\nlinear_momentum_drift = 1e-9\n");
  ScenarioLoad load = load_scenario_file(dir_ / "free.toml");
  ASSERT_TRUE(load.scene);
  const Scene scene = *load.scene;
  RunOptions options;
  options.isolate = false;
  const Reference reference = make_reference(scene, options);
  ASSERT_TRUE(reference.available);
  auto run_with = [&](std::function<void(BodyMeta&)> lie) {
    EngineFactory f;
    f.info = find_engine("core")->info;
    f.info.name = "liar";
    f.create = [lie] { return std::make_unique<MisreportingEngine>(lie); };
    RunRecord r = run_engine(scene, f, options);
    if (r.status == RunStatus::Ok) compare_run(r, scene, reference, true);
    return r;
  };
  // Honest about its bodies, it fails its drift limits (it loses energy).
  const RunRecord honest = run_with([](BodyMeta&) {});
  EXPECT_EQ(honest.status, RunStatus::Ok) << honest.reason;
  EXPECT_FALSE(honest.passed());
  for (auto lie : std::vector<std::function<void(BodyMeta&)>>{
           [](BodyMeta& m) { m.mass = 0.0; }, [](BodyMeta& m) { m.is_static = true; m.mass = 0.0; },
           [](BodyMeta& m) { m.mass *= 1e-3; }, [](BodyMeta& m) { m.radius = 0.0; }, [](BodyMeta& m) { m.name.push_back('2'); }}) {
    const RunRecord r = run_with(lie);
    EXPECT_EQ(r.status, RunStatus::Error) << r.reason;
    EXPECT_FALSE(r.passed());
    EXPECT_NE(r.reason.find("reports the scene's body 0 (\"a\")"), std::string::npos) << r.reason;
  }
}

// core slowing its one body 1% a step, with a phantom body (not in the scene) that takes
// up exactly the kinetic energy the scene's body loses.
class PhantomEngine : public Engine {
 public:
  PhantomEngine() : inner_(find_engine("core")->create()) {}
  const EngineInfo& info() const override { return inner_->info(); }
  void load(const Scene& scene) override { inner_->load(scene); }
  void step(double dt) override {
    inner_->step(dt);
    slowed_ *= 0.99;
  }
  double time() const override { return inner_->time(); }
  std::size_t body_count() const override { return inner_->body_count() + 1; }
  BodyMeta body_meta(std::size_t i) const override {
    return i < inner_->body_count() ? inner_->body_meta(i) : BodyMeta{"phantom", 1.0, 0.1, false};
  }
  void read_states(std::vector<BodyState>& out) const override {
    inner_->read_states(out);
    double lost = 0.0;
    for (std::size_t i = 0; i < out.size(); ++i) {
      const double m = inner_->body_meta(i).mass;
      lost += 0.5 * m * length_squared(out[i].velocity) * (1.0 - slowed_ * slowed_);
      out[i].velocity = slowed_ * out[i].velocity;
    }
    BodyState phantom = out.front();
    phantom.position = {0.0, 50.0};
    phantom.velocity = {0.0, std::sqrt(2.0 * lost / 1.0)};
    out.push_back(phantom);
  }
  const std::vector<ContactEvent>& contacts() const override { return inner_->contacts(); }
  std::vector<Setting> settings() const override { return inner_->settings(); }

 private:
  std::unique_ptr<Engine> inner_;
  double slowed_ = 1.0;
};

// An engine reporting more bodies than the scene has, in a scene without emitters (no
// particles can exist): the extra one was counted in the energy. One that took up the
// energy the scene's body lost read an energy drift of round-off, and an energy_drift
// gate of 1e-9 passed a run that lost 63% of its speed.
TEST_F(InfraHunt, AnEngineReportingBodiesTheSceneDoesNotHaveIsAnError) {
  put(dir_ / "free.toml", "name = \"free\"\nduration = 1.0\ndt = 0.01\n[[bodies]]\nname = \"a\"\nradius = 0.1\nmass = 2\n"
                          "position = [0, 0]\nvelocity = [1, 0]\n[gate]\nenergy_drift = 1e-9\n");
  ScenarioLoad load = load_scenario_file(dir_ / "free.toml");
  ASSERT_TRUE(load.scene);
  RunOptions options;
  options.isolate = false;
  const Reference reference = make_reference(*load.scene, options);
  EngineFactory f;
  f.info = find_engine("core")->info;
  f.info.name = "phantom";
  f.create = [] { return std::make_unique<PhantomEngine>(); };
  RunRecord r = run_engine(*load.scene, f, options);
  if (r.status == RunStatus::Ok) compare_run(r, *load.scene, reference, true);
  EXPECT_EQ(r.status, RunStatus::Error) << r.reason;
  EXPECT_FALSE(r.passed());
  EXPECT_NE(r.reason.find("reports 2 bodies, but the scene has 1 and no emitter"), std::string::npos) << r.reason;
}

// core, reporting every body destroyed (alive = false) from its third step on.
class VanishingEngine : public Engine {
 public:
  VanishingEngine() : inner_(find_engine("core")->create()) {}
  const EngineInfo& info() const override { return inner_->info(); }
  void load(const Scene& scene) override { inner_->load(scene); }
  void step(double dt) override {
    inner_->step(dt);
    ++steps_;
  }
  double time() const override { return inner_->time(); }
  std::size_t body_count() const override { return inner_->body_count(); }
  BodyMeta body_meta(std::size_t i) const override { return inner_->body_meta(i); }
  void read_states(std::vector<BodyState>& out) const override {
    inner_->read_states(out);
    if (steps_ >= 3) {
      for (BodyState& b : out) b.alive = false;
    }
  }
  const std::vector<ContactEvent>& contacts() const override { return inner_->contacts(); }
  std::vector<Setting> settings() const override { return inner_->settings(); }

 private:
  std::unique_ptr<Engine> inner_;
  int steps_ = 0;
};

// Positions of a body dead in either run are not compared (a destroy rule may remove it
// in one engine and not another). An engine reporting every body destroyed in a scene
// that destroys nothing was compared on nothing but energy and momentum: in a scene with
// friction (no energy conserved) a gate of position_divergence = 1e-6 passed it.
TEST_F(InfraHunt, AnEngineReportingBodiesDestroyedThatNothingDestroysIsAnError) {
  const std::string slide = "name = \"slide\"\nduration = 1.0\ndt = 0.01\n[world]\ngravity = [0, -9.81]\n"
                            "[[bodies]]\nname = \"a\"\nradius = 0.1\nmass = 2\nposition = [0, 0.1]\nvelocity = [3, 0]\n"
                            "friction = 0.5\n[[walls]]\nname = \"floor\"\nfrom = [-10, 0]\nto = [10, 0]\nfriction = 0.5\n"
                            "[gate]\nposition_divergence = 1e-6\n";
  put(dir_ / "slide.toml", slide);
  ScenarioLoad load = load_scenario_file(dir_ / "slide.toml");
  ASSERT_TRUE(load.scene) << (load.errors.empty() ? "" : load.errors.front().str());
  RunOptions options;
  options.isolate = false;
  const Reference reference = make_reference(*load.scene, options);
  ASSERT_TRUE(reference.available && reference.converged) << reference.reason;
  EngineFactory f;
  f.info = find_engine("core")->info;
  f.info.name = "vanishing";
  f.create = [] { return std::make_unique<VanishingEngine>(); };
  RunRecord r = run_engine(*load.scene, f, options);
  if (r.status == RunStatus::Ok) compare_run(r, *load.scene, reference, true);
  EXPECT_EQ(r.status, RunStatus::Error) << r.reason;
  EXPECT_FALSE(r.passed());
  EXPECT_NE(r.reason.find("destroyed, but nothing in the scene destroys it"), std::string::npos) << r.reason;
  // core itself, honest, passes the same gate.
  RunRecord honest = run_engine(*load.scene, *find_engine("core"), options);
  compare_run(honest, *load.scene, reference, true);
  EXPECT_TRUE(honest.passed()) << honest.reason;
}

// core, with its clock misreported: `scale` x the time it stepped (a plugin counting
// in another unit, or not counting the shortened last step).
class MistimedEngine : public Engine {
 public:
  explicit MistimedEngine(double scale) : inner_(find_engine("core")->create()), scale_(scale) {}
  const EngineInfo& info() const override { return inner_->info(); }
  void load(const Scene& scene) override { inner_->load(scene); }
  void step(double dt) override { inner_->step(dt); }
  double time() const override { return scale_ * inner_->time(); }
  std::size_t body_count() const override { return inner_->body_count(); }
  BodyMeta body_meta(std::size_t i) const override { return inner_->body_meta(i); }
  void read_states(std::vector<BodyState>& out) const override { inner_->read_states(out); }
  const std::vector<ContactEvent>& contacts() const override { return inner_->contacts(); }
  std::vector<Setting> settings() const override { return inner_->settings(); }

 private:
  std::unique_ptr<Engine> inner_;
  double scale_;
};

// Samples are paired with the reference's by their time, which is the engine's own
// clock: an engine whose clock ran at another rate had no sample paired after t = 0, and
// measured a position divergence of 0 whatever it did.
TEST_F(InfraHunt, AnEngineWhoseClockIsNotTheStepsIsAnError) {
  put(dir_ / "fall.toml", "name = \"fall\"\nduration = 1.0\ndt = 0.01\n[world]\ngravity = [0, -9.81]\n"
                          "[[bodies]]\nname = \"a\"\nradius = 0.1\nmass = 2\nposition = [0, 0]\nvelocity = [3, 0]\n"
                          "[gate]\nposition_divergence = 1e-6\n");
  ScenarioLoad load = load_scenario_file(dir_ / "fall.toml");
  ASSERT_TRUE(load.scene);
  RunOptions options;
  options.isolate = false;
  const Reference reference = make_reference(*load.scene, options);
  ASSERT_TRUE(reference.available && reference.converged) << reference.reason;
  for (double scale : {2.0, 1.0 + 1e-3, 0.0}) {
    EngineFactory f;
    f.info = find_engine("core")->info;
    f.info.name = "mistimed";
    f.create = [scale] { return std::make_unique<MistimedEngine>(scale); };
    RunRecord r = run_engine(*load.scene, f, options);
    if (r.status == RunStatus::Ok) compare_run(r, *load.scene, reference, true);
    EXPECT_EQ(r.status, RunStatus::Error) << scale << ": " << r.reason;
    EXPECT_FALSE(r.passed()) << scale;
    EXPECT_NE(r.reason.find("reports its time as"), std::string::npos) << r.reason;
  }
  EngineFactory honest;
  honest.info = find_engine("core")->info;
  honest.create = [] { return std::make_unique<MistimedEngine>(1.0); };
  RunRecord r = run_engine(*load.scene, honest, options);
  compare_run(r, *load.scene, reference, true);
  EXPECT_TRUE(r.passed()) << r.reason;
}

// --- -j's child processes: tried and right ------------------------------------------

// A child that ends its own process while stepping: with status 0 and no record, or after
// writing garbage onto every descriptor it holds (the record's pipe among them). Neither
// may come back `ok`; a healthy run beside them is unaffected.
TEST_F(InfraHunt, AChildThatExitsZeroOrWritesGarbageIsAnError) {
  put(dir_ / "free.toml", pair_scene("free", "-1"));
  ScenarioLoad load = load_scenario_file(dir_ / "free.toml");
  ASSERT_TRUE(load.scene);
  RunOptions options;
  options.isolate = true;
  // core, ending its process at the third step.
  class Ending : public Engine {
   public:
    explicit Ending(int how) : inner_(find_engine("core")->create()), how_(how) {}
    const EngineInfo& info() const override { return inner_->info(); }
    void load(const Scene& scene) override { inner_->load(scene); }
    void step(double dt) override {
      inner_->step(dt);
      if (++steps_ < 3) return;
      if (how_ == 1) {
        const char junk[] = "1rvp\0\0\0\0garbage that is no run record at all";
        for (int fd = 3; fd < 256; ++fd) (void)!::write(fd, junk, sizeof junk);
      }
      ::_exit(0);
    }
    double time() const override { return inner_->time(); }
    std::size_t body_count() const override { return inner_->body_count(); }
    BodyMeta body_meta(std::size_t i) const override { return inner_->body_meta(i); }
    void read_states(std::vector<BodyState>& out) const override { inner_->read_states(out); }
    const std::vector<ContactEvent>& contacts() const override { return inner_->contacts(); }
    std::vector<Setting> settings() const override { return inner_->settings(); }

   private:
    std::unique_ptr<Engine> inner_;
    int how_;
    int steps_ = 0;
  };
  auto engine_that = [](int how) {
    EngineFactory f;
    f.info = find_engine("core")->info;
    f.create = [how] { return std::make_unique<Ending>(how); };
    return f;
  };
  for (int how : {0, 1}) {
    const RunRecord r = run_engine_isolated(*load.scene, engine_that(how), options);
    EXPECT_EQ(r.status, RunStatus::Error) << how << ": " << r.reason;
    EXPECT_FALSE(r.passed());
  }
  const RunRecord fine = run_engine_isolated(*load.scene, *find_engine("core"), options);
  EXPECT_EQ(fine.status, RunStatus::Ok) << fine.reason;
}

}  // namespace
}  // namespace physval
