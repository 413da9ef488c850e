#pragma once
// Running the unchanged kestrel-kinect on a fakenect recording: Debian's fakenect library
// (in <libdir>/fakenect, from package libfreenect0.5, which libfreenect-dev pulls in) is put
// first on LD_LIBRARY_PATH and FAKENECT_PATH names the recording.

#include <filesystem>
#include <string>
#include <vector>

#include "test/support/test_support.h"

namespace kestrel::test {

/// The folder with fakenect's libfreenect.so (KESTREL_FAKENECT_DIR, set by the build).
inline std::string fakenect_library_dir() { return KESTREL_FAKENECT_DIR; }

inline bool fakenect_available() {
  std::error_code ec;
  return std::filesystem::exists(std::filesystem::path(fakenect_library_dir()) / "libfreenect.so.0.5", ec);
}

/// kestrel-kinect `args` on the recording in `dump`.
inline RunResult run_kinect(const std::filesystem::path& dump, const std::vector<std::string>& args,
                            double timeout_s = 120.0) {
  std::vector<std::string> argv = {"env", "LD_LIBRARY_PATH=" + fakenect_library_dir(),
                                   "FAKENECT_PATH=" + dump.string(), tool("kinect").string()};
  argv.insert(argv.end(), args.begin(), args.end());
  return run(argv, timeout_s);
}

}  // namespace kestrel::test

/// Skips the current test when Debian's fakenect library is not installed.
#define KESTREL_REQUIRE_FAKENECT()                                                         \
  if (!::kestrel::test::fakenect_available())                                              \
  KESTREL_SKIP_ENVIRONMENT() << ::kestrel::test::fakenect_library_dir()                                  \
               << "/libfreenect.so.0.5 is absent: these tests replay recordings through "  \
                  "Debian's fakenect (package libfreenect0.5)"
