#pragma once
// Helpers shared by the tests: where the data and the built tools are, temporary folders,
// and running a tool as a child process.

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace kestrel::test {

/// ../shared/data, or empty if it is absent.
std::filesystem::path shared_data();
/// shared_data()/tum/<name>; calls GTEST_SKIP-able check: returns empty if absent.
std::filesystem::path tum_sequence(const std::string& name);

/// <build>/bin/kestrel-<tool>.
std::filesystem::path tool(const std::string& name);
/// The repository's root (for its scripts, e.g. tools/demo/fly_to_goal).
std::filesystem::path source_dir();

/// The whole file's bytes (empty if it cannot be read).
std::string read_file(const std::filesystem::path& path);

/// A fresh folder, removed at destruction unless the running test has failed: then it stays,
/// with the processes' logs and flight logs a failure needs, and its path is printed.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

struct RunResult {
  int exit_code = -1;  ///< exit status, or 128 + signal
  std::string out;
  std::string err;
};
/// Runs argv[0] with the rest as arguments, waits at most `timeout_s`, captures stdout/stderr.
RunResult run(const std::vector<std::string>& argv, double timeout_s = 120.0);

/// A shell command that returns once a socket in the current network namespace listens on the
/// port of kestrel's default LCM URL, i.e. once an lcm-logger started before it has subscribed
/// (a fixed sleep was not always enough on a loaded machine); after `timeout_s` it exits the
/// script with status 98. Meant for a private namespace, where only the logger listens yet.
std::string wait_for_lcm_listener_sh(double timeout_s = 20.0);

/// True if this process may create a network namespace (root or unprivileged user
/// namespaces); integration tests that need one skip otherwise.
bool can_isolate_network();

/// Runs `script` with sh in a private network namespace whose loopback carries multicast
/// (kestrel-isolated, tools/launch/README.md), so the LCM traffic of the processes it starts stays there.
RunResult run_isolated(const std::string& script, double timeout_s = 120.0);

/// In a sanitizer build, where this test process's children write their sanitizer reports
/// (ASAN_OPTIONS etc. carry log_path=<this>/report for them); empty in other builds. A report
/// that appears there fails the test during which it appeared (test_support.cpp).
std::filesystem::path child_sanitizer_report_dir();
/// The children's reports that appeared since the last call (or since the last test ended),
/// each as "<file>:\n<text>"; those taken here no longer fail the test.
std::vector<std::string> take_child_sanitizer_reports();

/// `s` in single quotes for sh.
std::string quoted(const std::string& s);

/// Whether a test that cannot run here (no network namespace, no ../shared/data, a tool or a
/// system program missing) fails instead of skipping. Under CI=true every environment the
/// suite needs is provided, so a skip there is a set-up step that went missing, not a pass.
/// The message of the InputError that `f` throws, or "(no InputError)" when it throws none
/// (any other exception propagates, failing the test).
std::string input_error_of(const std::function<void()>& f);

inline bool environmental_skips_fail() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string(ci) == "true";
}

}  // namespace kestrel::test

/// Skips the current test because its environment is missing, with the message streamed after
/// it; under CI=true (environmental_skips_fail) the same line is a fatal failure instead.
/// Spelled like GTEST_SKIP (GoogleTest's own message helper), so it streams the same way and,
/// like it, only returns from a function returning void.
#define KESTREL_SKIP_ENVIRONMENT()                                                              \
  return ::testing::internal::AssertHelper(                                                     \
             ::kestrel::test::environmental_skips_fail() ? ::testing::TestPartResult::kFatalFailure \
                                                         : ::testing::TestPartResult::kSkip,     \
             __FILE__, __LINE__,                                                                 \
             ::kestrel::test::environmental_skips_fail()                                         \
                 ? "CI=true, where a missing environment fails the test"                        \
                 : "Skipped") = ::testing::Message()

/// Skips the current test with a clear message when ../shared/data/tum/<name> is absent.
#define KESTREL_REQUIRE_TUM(var, name)                                                    \
  const std::filesystem::path var = ::kestrel::test::tum_sequence(name);                  \
  if (var.empty())                                                                         \
  KESTREL_SKIP_ENVIRONMENT() << "../shared/data/tum/" << (name)                                          \
               << " is absent: this test needs the real TUM RGB-D sequence"
