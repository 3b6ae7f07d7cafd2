// The command line of `-j` and the reference cache: bad values are usage errors, and a
// second run with the same cache reads the entries the first wrote, with the same results.
#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

namespace {

namespace fs = std::filesystem;

int physval(const std::string& args) {
  const int status = std::system((std::string(PHYSVAL_EXE) + " " + args + " >/dev/null 2>&1").c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::string read(const fs::path& f) {
  std::ifstream in(f);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

TEST(ScaleCli, NegativeJobsIsAUsageError) {
  EXPECT_EQ(physval("run " PHYSVAL_SOURCE_SCENARIOS "/basics --jobs -1 --no-cache --quiet --out /dev/null/x"), 2);
}

TEST(ScaleCli, SecondRunReadsTheCacheTheFirstWrote) {
  const fs::path root = fs::temp_directory_path() / ("physval-scale-cli-" + std::to_string(::getpid()));
  fs::remove_all(root);
  const std::string scenes = " " PHYSVAL_SOURCE_SCENARIOS "/basics --quiet --engines core";
  const std::string common = scenes + " -j 2 --cache " + (root / "cache").string();
  ASSERT_EQ(physval("run" + common + " --out " + (root / "a").string()), 0);
  std::size_t entries = 0;
  for (const auto& e : fs::directory_iterator(root / "cache")) entries += e.path().extension() == ".ref" ? 1 : 0;
  EXPECT_EQ(entries, 3u);   // one per scenario in basics/
  const auto written = fs::last_write_time(fs::directory_iterator(root / "cache")->path());
  ASSERT_EQ(physval("run" + common + " --out " + (root / "b").string()), 0);
  EXPECT_EQ(fs::last_write_time(fs::directory_iterator(root / "cache")->path()), written);   // read, not rewritten
  ASSERT_EQ(physval("run" + scenes + " --no-cache -j 1 --out " + (root / "c").string()), 0);
  // The per-engine series (no timings in them) are identical with and without the cache, at -j 2 and -j 1.
  for (const char* f : {"series/head_on_elastic/core.bin", "series/equal_mass_swap/core.bin"}) {
    EXPECT_EQ(read(root / "a" / f), read(root / "c" / f)) << f;
    EXPECT_EQ(read(root / "b" / f), read(root / "c" / f)) << f;
    EXPECT_FALSE(read(root / "a" / f).empty()) << f;
  }
  fs::remove_all(root);
}

}  // namespace
