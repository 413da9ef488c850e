#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <system_error>

#include "fuzz/groups.h"
#include "fuzz/target.h"

namespace kestrel::fuzz {

const std::vector<Target>& targets() {
  static const std::vector<Target> all = [] {
    std::vector<Target> v;
    for (auto group : {message_targets, text_targets, image_targets, journal_targets, slam_map_targets,
                       estimator_targets}) {
      for (Target& t : group()) v.push_back(t);
    }
#if KESTREL_FUZZ_STATION
    for (Target& t : station_targets()) v.push_back(t);  // built only with station/
#endif
    return v;
  }();
  return all;
}

const Target* find_target(std::string_view name) {
  for (const Target& t : targets()) {
    if (name == t.name) return &t;
  }
  return nullptr;
}

void defect(const std::string& target, const std::string& what) {
  std::fprintf(stderr, "kestrel-fuzz: %s: defect: %s\n", target.c_str(), what.c_str());
  std::fflush(stderr);
  std::abort();
}

namespace {

namespace fs = std::filesystem;

// The folder lives as long as the process: libFuzzer runs millions of inputs in one process,
// and readers that take a path get a file there rewritten for each.
struct ScratchDir {
  std::string path;
  ScratchDir() {
    const char* tmp = std::getenv("TMPDIR");
    path = (fs::path(tmp && *tmp ? tmp : "/tmp") / ("kestrel-fuzz-" + std::to_string(getpid()))).string();
    fs::create_directories(path);
  }
  ~ScratchDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
};

}  // namespace

const std::string& scratch_dir() {
  static const ScratchDir dir;
  return dir.path;
}

std::string scratch_file(const std::string& name, const uint8_t* data, size_t size) {
  const std::string path = scratch_dir() + "/" + name;
  // in-place: input for the code under test, in a scratch folder of its own
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  out.close();
  if (!out) defect("scratch", "cannot write " + path);
  return path;
}

std::string scratch_file(const std::string& name, std::string_view text) {
  return scratch_file(name, reinterpret_cast<const uint8_t*>(text.data()), text.size());
}

Bytes file_bytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) defect("scratch", "cannot read " + path);
  return Bytes(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

}  // namespace kestrel::fuzz
