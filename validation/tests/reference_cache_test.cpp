// The reference cache: a second run reads what the first stored, any change to what the
// reference depends on misses, a damaged entry is recomputed, concurrent runs agree.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <thread>

#include "physval/validation/reference_cache.hpp"
#include "physval/validation/scenario_loader.hpp"

namespace physval {
namespace {

namespace fs = std::filesystem;

class ReferenceCache : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("physval-refcache-test-" + std::to_string(::getpid()));
    fs::remove_all(root_);
    fs::create_directories(root_);
    options_.reference_cache = (root_ / "cache").string();
  }
  void TearDown() override { fs::remove_all(root_); }

  Scene write_and_load(const std::string& velocity) {
    const fs::path file = root_ / "pair.toml";
    std::ofstream(file) << "name = \"pair\"\nduration = 1.0\ndt = 0.01\n"
                           "[[bodies]]\nname = \"a\"\nradius = 0.1\nmass = 1\nposition = [0, 0]\nvelocity = ["
                        << velocity << ", 0]\n[[bodies]]\nname = \"b\"\nradius = 0.1\nmass = 2\nposition = [1, 0]\n";
    ScenarioLoad load = load_scenario_file(file);
    if (!load.scene) throw std::runtime_error("test scene does not load");
    return *load.scene;
  }

  std::size_t entries() const {
    std::size_t n = 0;
    for (const auto& e : fs::directory_iterator(root_ / "cache")) n += e.path().extension() == ".ref" ? 1 : 0;
    return n;
  }

  fs::path root_;
  RunOptions options_;
};

void expect_same(const Reference& a, const Reference& b) {
  EXPECT_EQ(a.available, b.available);
  EXPECT_EQ(a.converged, b.converged);
  EXPECT_EQ(a.reason, b.reason);
  EXPECT_EQ(a.dt, b.dt);
  EXPECT_EQ(a.convergence_error, b.convergence_error);
  ASSERT_TRUE(a.run && b.run);
  EXPECT_EQ(a.run->series.time, b.run->series.time);
  ASSERT_EQ(a.run->series.states.size(), b.run->series.states.size());
  EXPECT_EQ(a.run->series.states.back().back().position.x, b.run->series.states.back().back().position.x);
  EXPECT_EQ(a.run->contacts.size(), b.run->contacts.size());
}

TEST_F(ReferenceCache, SecondRunReadsTheStoredReference) {
  const Scene scene = write_and_load("2");
  const CachedReference first = cached_reference(scene, options_);
  ASSERT_TRUE(first.reference.available) << first.reference.reason;
  EXPECT_FALSE(first.from_cache);
  const CachedReference second = cached_reference(scene, options_);
  EXPECT_TRUE(second.from_cache);
  expect_same(first.reference, second.reference);
  EXPECT_EQ(entries(), 1u);
}

TEST_F(ReferenceCache, ChangedSceneStepOrSamplingMisses) {
  const Scene scene = write_and_load("2");
  (void)cached_reference(scene, options_);
  Scene finer = scene;
  finer.dt = 0.005;
  EXPECT_FALSE(cached_reference(finer, options_).from_cache);
  RunOptions fewer = options_;
  fewer.max_sample_states = 1000;
  EXPECT_FALSE(cached_reference(scene, fewer).from_cache);
  const Scene faster = write_and_load("3");   // same name, other file text
  const CachedReference changed = cached_reference(faster, options_);
  EXPECT_FALSE(changed.from_cache);
  EXPECT_EQ(entries(), 4u);
  EXPECT_TRUE(cached_reference(faster, options_).from_cache);
}

TEST_F(ReferenceCache, DamagedEntryIsRecomputedAndReplaced) {
  const Scene scene = write_and_load("2");
  const CachedReference first = cached_reference(scene, options_);
  for (const auto& e : fs::directory_iterator(root_ / "cache")) std::ofstream(e.path(), std::ios::trunc) << "garbage";
  const CachedReference again = cached_reference(scene, options_);
  EXPECT_FALSE(again.from_cache);
  expect_same(first.reference, again.reference);
  EXPECT_TRUE(cached_reference(scene, options_).from_cache);
}

TEST_F(ReferenceCache, NoCacheFolderMeansNoCache) {
  const Scene scene = write_and_load("2");
  RunOptions none = options_;
  none.reference_cache.clear();
  (void)cached_reference(scene, none);
  EXPECT_FALSE(cached_reference(scene, none).from_cache);
  EXPECT_FALSE(fs::exists(root_ / "cache"));
}

TEST_F(ReferenceCache, ConcurrentWritersLeaveOneWholeEntry) {
  const Scene scene = write_and_load("2");
#if defined(__SANITIZE_ADDRESS__)
  // A child forked from one of several threads can hang inside libasan (the reason the
  // sanitizer build's scheduler runs one task at a time): the references are computed in
  // these threads' own process there; the writers still race on the cache entry.
  options_.isolate = false;
#endif
  std::vector<CachedReference> got(4);
  std::vector<std::thread> threads;
  for (std::size_t i = 0; i < got.size(); ++i) {
    threads.emplace_back([&, i] { got[i] = cached_reference(scene, options_); });
  }
  for (std::thread& t : threads) t.join();
  for (const CachedReference& r : got) expect_same(got[0].reference, r.reference);
  std::size_t files = 0;
  for (const auto& e : fs::directory_iterator(root_ / "cache")) {
    (void)e;
    ++files;
  }
  EXPECT_EQ(files, 1u);   // no temporary file left behind
  EXPECT_TRUE(cached_reference(scene, options_).from_cache);
}

}  // namespace
}  // namespace physval
