// What the harness holds per body on the 100k-body scene (a generated gas):
// under 1 kB a body in the parent above the loaded scene, from reference to results.json
// (it was 1.6 kB before the reference's scene variants were released early, and several
// kB before the binary record stream and the streamed results.json). Also: the streamed
// results.json is byte for byte the JSON tree's dump, and a record survives its bytes.
#include <gtest/gtest.h>

#include <fcntl.h>
#include <malloc.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <thread>

#include "physval/validation/results_json.hpp"
#include "physval/validation/run_record_io.hpp"
#include "physval/validation/scenario_loader.hpp"
#include "physval/validation/suite.hpp"

namespace {

namespace fs = std::filesystem;

// A gas of n circles on a grid in a walled box, random velocities, `steps` steps of 1/60 s.
std::string gas(std::size_t n, int steps) {
  std::ostringstream os;
  os.precision(9);
  const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  const double spacing = 0.25, half = static_cast<double>(side) * spacing / 2.0 + 0.5;
  os << "name = \"gas_" << n << "\"\ndt = 0.0166666666666666667\nduration = " << (steps / 60.0) << "\n[core]\nbroadphase = \"grid\"\n";
  const double w[4][4] = {{-half, -half, -half, half}, {half, -half, half, half}, {-half, -half, half, -half}, {-half, half, half, half}};
  for (int k = 0; k < 4; ++k) {
    os << "[[walls]]\nname = \"w" << k << "\"\nfrom = [" << w[k][0] << ", " << w[k][1] << "]\nto = [" << w[k][2] << ", "
       << w[k][3] << "]\n";
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> v(-1.0, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    const double x = static_cast<double>(i % side) * spacing - half + 0.5 + spacing / 2.0;
    const double y = static_cast<double>(i / side) * spacing - half + 0.5 + spacing / 2.0;
    os << "[[bodies]]\nname = \"c" << i << "\"\nradius = 0.05\nposition = [" << x << ", " << y << "]\nvelocity = ["
       << v(rng) << ", " << v(rng) << "]\n";
  }
  return os.str();
}

long status_kb(const char* key) {
  std::ifstream in("/proc/self/status");
  std::string line;
  while (std::getline(in, line)) {
    if (line.rfind(key, 0) == 0) return std::stol(line.substr(std::string(key).size()));
  }
  return -1;
}

// The scene size: 100k circles. The scene is loaded first (the TOML loader's
// own peak is not the harness's), then the peak is reset (/proc/self/clear_refs 5) and
// the suite runs on core with its reference, compared and written to results.json. The
// parent's new peak above its resident size at the reset is the harness's share; an
// engine child's peak above that same size is the engine's state plus the child's
// record (its series, streamed out through a 64 KiB buffer).
#if defined(__SANITIZE_ADDRESS__)
#define PHYSVAL_MEMORY_INSTRUMENTED 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(memory_sanitizer)
#define PHYSVAL_MEMORY_INSTRUMENTED 1
#endif
#endif

TEST(Memory, HarnessHoldsUnderOneKilobyteABodyOnA100kBodyRun) {
#ifdef PHYSVAL_MEMORY_INSTRUMENTED
  GTEST_SKIP() << "a sanitizer's shadow memory and redzones are not physval's; the Release build measures this";
#endif
  const fs::path root = fs::temp_directory_path() / ("physval-memory-" + std::to_string(::getpid()));
  fs::remove_all(root);
  fs::create_directories(root);
  constexpr std::size_t kBodies = 100000;
  physval::ScenarioLoad load = physval::parse_scenario(gas(kBodies, 8), "gas.toml");
  ASSERT_TRUE(load.scene);
  std::vector<physval::Scene> scenes{std::move(*load.scene)};
  load = physval::ScenarioLoad{};
  ::malloc_trim(0);
  { std::ofstream("/proc/self/clear_refs") << "5"; }
  const long base_kb = status_kb("VmRSS:");
  ASSERT_GT(base_kb, 0);
  ASSERT_LE(status_kb("VmHWM:"), base_kb + 1024) << "the peak was not reset (needs Linux >= 4.0)";
  physval::RunOptions options;   // isolated runs, no cache: the reference is computed
  physval::SuiteResult result = physval::run_suite(std::move(scenes), {"core"}, options, false, {}, 1);
  ASSERT_EQ(result.scenarios.at(0).runs.size(), 1u);
  EXPECT_EQ(result.scenarios[0].runs[0].status, physval::RunStatus::Ok) << result.scenarios[0].runs[0].reason;
  EXPECT_TRUE(result.scenarios[0].reference.available);
  physval::write_results(root / "out", result);
  const long parent_peak_kb = status_kb("VmHWM:");
  rusage children{};
  ::getrusage(RUSAGE_CHILDREN, &children);
  const double parent_b = 1024.0 * static_cast<double>(parent_peak_kb - base_kb) / kBodies;
  const double child_b = 1024.0 * static_cast<double>(children.ru_maxrss - base_kb) / kBodies;
  std::cout << "resident after loading " << base_kb << " kB; parent peak +" << parent_b << " B a body; engine child peak +"
            << child_b << " B a body\n";
  EXPECT_LT(parent_b, 1024.0);
  EXPECT_LT(child_b, 1024.0 + 1024.0);   // the engine's own state (core: about 164 B a body) and the child's record
  fs::remove_all(root);
}

TEST(Memory, StreamedResultsJsonIsTheTreesDump) {
  std::vector<physval::Scene> scenes;
  for (const char* f : {"/basics/head_on_elastic.toml", "/models/particles_explosion.toml", "/hard/newtons_cradle.toml"}) {
    physval::ScenarioLoad load = physval::load_scenario_file(std::string(PHYSVAL_SOURCE_SCENARIOS) + f);
    ASSERT_TRUE(load.scene) << f;
    scenes.push_back(*load.scene);
  }
  physval::SuiteResult result = physval::run_suite(scenes, {}, physval::RunOptions{}, true, {}, 2);
  result.shard = {{"index", 0}, {"count", 1}};
  std::ostringstream streamed;
  physval::write_results_json(streamed, result);
  // The context's date may tick between the two: compare with it taken from the stream.
  nlohmann::json tree = physval::suite_to_json(result);
  tree["context"] = nlohmann::json::parse(streamed.str())["context"];
  EXPECT_EQ(streamed.str(), tree.dump(2) + "\n");
  EXPECT_FALSE(result.scenarios[0].runs.front().contacts.empty());
}

TEST(Memory, RunRecordSurvivesTheByteStream) {
  physval::RunRecord r;
  r.scenario = "s";
  r.engine = "core";
  r.status = physval::RunStatus::Diverged;
  r.diverged_at = 0.5;
  r.settings = {{"integrator", "rk4"}};
  r.bodies = {{"a", 1.0, 0.5, false}, {"wall", 0.0, 0.0, true}};
  r.contacts = {{"a", "wall", 0.25, 15}};
  r.series.time = {0.0, 0.1};
  r.series.totals.resize(2);
  r.series.totals[1].kinetic = 3.0;
  r.series.states = {physval::SampleRow{{{1.0, 2.0}, true}, {{3.0, 4.0}, false}}, physval::SampleRow{}};
  r.final_states.resize(1);
  r.final_states[0].velocity = {-1.0, std::nan("")};
  const std::vector<std::uint8_t> bytes = physval::encode_run_record(r);
  const physval::RunRecord back = physval::decode_run_record(bytes);
  EXPECT_EQ(back.status, r.status);
  EXPECT_EQ(back.diverged_at, r.diverged_at);
  EXPECT_EQ(back.settings, r.settings);
  EXPECT_EQ(back.bodies[1].is_static, true);
  EXPECT_EQ(back.contacts[0].step, 15);
  EXPECT_EQ(back.series.totals[1].kinetic, 3.0);
  ASSERT_EQ(back.series.states.size(), 2u);
  EXPECT_EQ(back.series.states[0][1].position.y, 4.0);
  EXPECT_FALSE(back.series.states[0][1].alive);
  EXPECT_TRUE(std::isnan(back.final_states[0].velocity.y));
  // Truncated or damaged bytes are refused, never read as another record.
  for (std::size_t cut : {std::size_t{0}, std::size_t{7}, bytes.size() / 2, bytes.size() - 1}) {
    EXPECT_THROW(physval::decode_run_record(std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + static_cast<long>(cut))),
                 std::runtime_error)
        << cut;
  }
}

// The series crosses as blocks read into place (run_record_io.cpp): rows of different sizes
// (particles appear), through a pipe whose writer and reader meet it in pieces, and past
// the size read at once (4M states), row by row; an alive flag that is no bool is refused.
TEST(Memory, SeriesBlocksSurviveThePipeInPlace) {
  auto record = [](std::size_t rows, std::size_t first, std::size_t growth) {
    physval::RunRecord r;
    r.scenario = "s";
    r.engine = "core";
    for (std::size_t k = 0; k < rows; ++k) {
      r.series.time.push_back(0.1 * static_cast<double>(k));
      physval::Totals t;
      t.kinetic = static_cast<double>(k);
      t.angular_momentum = -static_cast<double>(k);
      r.series.totals.push_back(t);
      physval::SampleRow row(first + k * growth);
      for (std::size_t i = 0; i < row.size(); ++i) row[i] = {{static_cast<double>(k), static_cast<double>(i)}, (i + k) % 3 != 0};
      r.series.states.push_back(row);
    }
    return r;
  };
  auto same = [](const physval::RunRecord& a, const physval::RunRecord& b) {
    ASSERT_EQ(a.series.time, b.series.time);
    ASSERT_EQ(a.series.states.size(), b.series.states.size());
    for (std::size_t k = 0; k < a.series.states.size(); ++k) {
      EXPECT_EQ(a.series.totals[k].kinetic, b.series.totals[k].kinetic);
      EXPECT_EQ(a.series.totals[k].angular_momentum, b.series.totals[k].angular_momentum);
      const auto x = a.series.states[k], y = b.series.states[k];
      ASSERT_EQ(x.size(), y.size()) << k;
      for (std::size_t i = 0; i < x.size(); ++i) {
        ASSERT_EQ(x[i].position.x, y[i].position.x);
        ASSERT_EQ(x[i].position.y, y[i].position.y);
        ASSERT_EQ(x[i].alive, y[i].alive);
      }
    }
  };
  // Through a pipe, written by another thread: 50 rows of 2,000 to 2,049 states, 2.4 MB.
  const physval::RunRecord piped = record(50, 2000, 1);
  int fds[2];
  ASSERT_EQ(::pipe(fds), 0);
  std::thread writer([&] {
    EXPECT_TRUE(physval::write_run_record(fds[1], piped));
    ::close(fds[1]);
  });
  std::size_t bytes = 0;
  const physval::RunRecord back = physval::read_run_record(fds[0], std::nullopt, bytes);
  writer.join();
  ::close(fds[0]);
  EXPECT_GT(bytes, 50u * 2000u * sizeof(physval::SampleState));
  same(piped, back);
  // Past 4M states: read row by row (5 rows of 900,000 states).
  const physval::RunRecord big = record(5, 900000, 0);
  same(big, physval::decode_run_record(physval::encode_run_record(big)));
  // An alive flag of 2 in the block is refused.
  std::vector<std::uint8_t> damaged = physval::encode_run_record(record(3, 10, 2));
  // The last state's flag: right after its position (2, 13), the last such pair of doubles.
  const double last[2] = {2.0, 13.0};
  const auto* pattern = reinterpret_cast<const std::uint8_t*>(last);
  const auto at = std::find_end(damaged.begin(), damaged.end(), pattern, pattern + sizeof last);
  ASSERT_NE(at, damaged.end());
  const std::size_t flag = static_cast<std::size_t>(at - damaged.begin()) + sizeof last;
  ASSERT_EQ(damaged[flag], 0);   // (13 + 2) % 3 == 0: not alive
  bool refused = false;
  damaged[flag] = 2;
  try {
    (void)physval::decode_run_record(damaged);
  } catch (const std::runtime_error& e) {
    refused = std::string(e.what()).find("flag") != std::string::npos;
  }
  EXPECT_TRUE(refused);
}

}  // namespace
