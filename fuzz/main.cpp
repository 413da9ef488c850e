// kestrel-fuzz: runs one fuzz target (fuzz/target.h) under libFuzzer. `./kestrel fuzz` builds
// it (the fuzz build, KESTREL_FUZZ) and drives every target; see fuzz/README.md.
//
//   kestrel-fuzz TARGET [libFuzzer options] [CORPUS...]   fuzz (or, given files, run them)
//   kestrel-fuzz --list                                   the targets and what each reads
//   kestrel-fuzz --seeds TARGET DIR                       write TARGET's seeds into DIR

#include <spdlog/spdlog.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <exception>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "fuzz/target.h"

extern "C" int LLVMFuzzerRunDriver(int* argc, char*** argv, int (*callback)(const uint8_t* data, size_t size));

namespace {

const kestrel::fuzz::Target* g_target = nullptr;
constexpr const char* kTargetVariable = "KESTREL_FUZZ_TARGET";

int one_input(const uint8_t* data, size_t size) {
  g_target->run(data, size);
  return 0;
}

int usage() {
  std::fprintf(stderr,
               "usage: kestrel-fuzz TARGET [libFuzzer options] [CORPUS...]\n"
               "       kestrel-fuzz --list\n"
               "       kestrel-fuzz --seeds TARGET DIR\n");
  return 2;
}

const kestrel::fuzz::Target* target_named(const char* name) {
  const auto* t = kestrel::fuzz::find_target(name);
  if (!t) std::fprintf(stderr, "kestrel-fuzz: error: no target '%s' (kestrel-fuzz --list names them)\n", name);
  return t;
}

int write_seeds(const kestrel::fuzz::Target& t, const std::string& dir) {
  try {
    std::filesystem::create_directories(dir);
    int i = 0;
    for (const auto& seed : t.seeds())
      kestrel::write_file_atomically(dir + "/seed-" + std::to_string(i++), seed.data(), seed.size());
  } catch (const std::exception& e) {  // the folder or a file cannot be written
    std::fprintf(stderr, "kestrel-fuzz: error: %s: %s\n", dir.c_str(), e.what());
    return 3;
  }
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  // The libraries' warnings about the inputs they refuse would drown libFuzzer's lines.
  spdlog::set_level(spdlog::level::off);
  if (argc < 2) return usage();
  if (std::strcmp(argv[1], "--list") == 0) {
    for (const auto& t : kestrel::fuzz::targets()) std::printf("%-24s %s\n", t.name, t.reads);
    return 0;
  }
  if (std::strcmp(argv[1], "--seeds") == 0) {
    if (argc != 4) return usage();
    const auto* t = target_named(argv[2]);
    return t ? write_seeds(*t, argv[3]) : 2;
  }
  // libFuzzer starts itself again for -merge, -fork and -minimize_crash with its own options
  // only: the target's name then comes from the environment its first run set.
  int first_option = 2;
  const char* inherited = std::getenv(kTargetVariable);
  if (argv[1][0] == '-' && inherited) {
    g_target = target_named(inherited);
    first_option = 1;
  } else if (argv[1][0] == '-') {
    return usage();
  } else {
    g_target = target_named(argv[1]);
  }
  if (!g_target) return 2;
  setenv(kTargetVariable, g_target->name, 1);
  // libFuzzer reads its options from argv[1] on: the target's name is not one of them.
  std::vector<char*> args{argv[0]};
  args.insert(args.end(), argv + first_option, argv + argc);
  args.push_back(nullptr);
  int n = static_cast<int>(args.size()) - 1;
  char** p = args.data();
  return LLVMFuzzerRunDriver(&n, &p, one_input);
}
