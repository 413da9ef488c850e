// The fuzz targets (fuzz/target.h) on what is known about them, in every `./kestrel test`:
//  * each target's seeds, made by kestrel's own writers, are accepted: a decoder that refused
//    well-formed input (or a target that tested nothing) fails here;
//  * every input committed under fuzz/corpus/<target>/ (what `./kestrel fuzz` found: inputs
//    that crashed once and were fixed, and the coverage corpus) runs to an end;
//  * each seed cut at every length (or 48 of them), with the bytes at as many places flipped,
//    and with runs of zeros and of 0xff, runs to an end: the damage a link or a disk does,
//    tried deterministically.
// "Runs to an end" is the contract of common/error.h: accepted, or refused with InputError;
// any other exception fails the test and a crash or sanitizer report ends it.

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <set>
#include <string>

#include "fuzz/target.h"

namespace kestrel::fuzz {
namespace {

namespace fs = std::filesystem;

const fs::path kCorpus = fs::path(KESTREL_SOURCE_DIR) / "fuzz" / "corpus";

std::vector<std::string> target_names() {
  std::vector<std::string> names;
  for (const Target& t : targets()) names.emplace_back(t.name);
  return names;
}

// Runs `input` from a copy of just its size, so that AddressSanitizer sees a read past its end.
bool run_exactly(const Target& target, const Bytes& input) {
  const auto copy = std::make_unique<uint8_t[]>(std::max<size_t>(input.size(), 1));
  std::copy(input.begin(), input.end(), copy.get());
  return target.run(copy.get(), input.size());
}

class FuzzTarget : public ::testing::TestWithParam<std::string> {
 protected:
  const Target& target() const { return *find_target(GetParam()); }
  bool run(const Bytes& input) const { return run_exactly(target(), input); }
};

TEST_P(FuzzTarget, AcceptsEveryOneOfItsSeeds) {
  const auto seeds = target().seeds();
  ASSERT_FALSE(seeds.empty());
  for (size_t i = 0; i < seeds.size(); ++i) EXPECT_TRUE(run(seeds[i])) << "seed " << i << " refused";
}

TEST_P(FuzzTarget, RunsEveryDamagedSeedToAnEnd) {
  for (const Bytes& seed : target().seeds()) {
    // Every length for a small seed; 48 spread over a large one (and its last 8), and as many
    // places to damage: ~250 runs a seed, so that a seed that takes a 50 ms run (the
    // estimator's stream under the sanitizers) costs seconds, not minutes.
    const size_t step = std::max<size_t>(1, seed.size() / 48);
    for (size_t n = 0; n < seed.size(); n += step) run(Bytes(seed.begin(), seed.begin() + static_cast<std::ptrdiff_t>(n)));
    for (size_t n = seed.size() - std::min<size_t>(seed.size(), 8); n < seed.size(); ++n) {
      run(Bytes(seed.begin(), seed.begin() + static_cast<std::ptrdiff_t>(n)));
    }
    for (size_t i = 0; i < seed.size(); i += step) {
      for (const uint8_t mask : {0x01, 0x80, 0xff}) {
        Bytes flipped = seed;
        flipped[i] ^= mask;
        run(flipped);
      }
    }
    for (const uint8_t fill : {0x00, 0xff}) {
      for (size_t i = 0; i < seed.size(); i += 4 * step) {
        Bytes run_of = seed;
        std::fill(run_of.begin() + static_cast<std::ptrdiff_t>(i),
                  run_of.begin() + static_cast<std::ptrdiff_t>(std::min(seed.size(), i + 16)), fill);
        run(run_of);
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Each, FuzzTarget, ::testing::ValuesIn(target_names()),
                         [](const auto& test_param) {
                           std::string name = test_param.param;
                           std::replace(name.begin(), name.end(), '-', '_');
                           return name;
                         });

// Every input committed for any target (only the targets fuzzing found something for, or
// whose corpus was merged in, have a folder).
TEST(FuzzTargets, RunEveryCommittedInputToAnEnd) {
  ASSERT_TRUE(fs::is_directory(kCorpus)) << kCorpus;
  int n = 0;
  for (const auto& folder : fs::directory_iterator(kCorpus)) {
    const Target* target = find_target(folder.path().filename().string());
    ASSERT_NE(target, nullptr) << folder.path() << " names no target";
    for (const auto& e : fs::directory_iterator(folder.path())) {
      std::ifstream in(e.path(), std::ios::binary);
      const Bytes input((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
      SCOPED_TRACE(e.path().string());
      run_exactly(*target, input);
      ++n;
    }
  }
  EXPECT_GT(n, 0) << "no corpus under " << kCorpus;
}

TEST(FuzzTargets, NamesAreUniqueAndEveryCorpusFolderIsATarget) {
  std::set<std::string> names;
  for (const Target& t : targets()) EXPECT_TRUE(names.insert(t.name).second) << t.name << " twice";
  if (!fs::exists(kCorpus)) return;
  for (const auto& e : fs::directory_iterator(kCorpus)) {
    EXPECT_TRUE(names.count(e.path().filename().string())) << e.path() << " names no target";
  }
}

}  // namespace
}  // namespace kestrel::fuzz
