// The sanitizer builds' harness: a tool's sanitizer report, in a child process as the tests
// run the tools, goes to the test process's folder (not to the child's stderr, which tests
// read), and fails the test during which it appeared (test/support/test_support.cpp).
#include <signal.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "test/support/test_support.h"

#if defined(__has_feature)
#if __has_feature(address_sanitizer)
#define KESTREL_PROBE_ASAN 1
#endif
#if __has_feature(thread_sanitizer)
#define KESTREL_PROBE_TSAN 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__)
#define KESTREL_PROBE_ASAN 1
#endif
#if defined(__SANITIZE_THREAD__)
#define KESTREL_PROBE_TSAN 1
#endif

namespace kestrel::test {
namespace {

std::string probe() { return (std::filesystem::path(KESTREL_BINARY_DIR) / "test" / "kestrel_sanitizer_probe").string(); }

// The defect of this build's sanitizer that the probe commits.
#ifdef KESTREL_PROBE_TSAN
const char* const kDefect = "data-race";
const char* const kReport = "WARNING: ThreadSanitizer: data race";
const char* const kOptions = "TSAN_OPTIONS";
#else
const char* const kDefect = "heap-overflow";
const char* const kReport = "ERROR: AddressSanitizer: heap-buffer-overflow";
const char* const kOptions = "ASAN_OPTIONS";
#endif

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// The one report the probe run `defect` wrote, checked to be the probe's and to name `what`;
// and checked not to be on the probe's stderr.
void expect_one_report(const std::string& defect, const std::string& what) {
  const RunResult r = run({probe(), defect}, 60.0);
  EXPECT_NE(r.exit_code, 0) << "the probe's " << defect << " went unreported";
  EXPECT_FALSE(contains(r.err, what)) << "the report went to the child's stderr:\n" << r.err;
  const std::vector<std::string> reports = take_child_sanitizer_reports();
  ASSERT_EQ(reports.size(), 1u) << "probe " << defect << ", stderr:\n" << r.err;
  EXPECT_TRUE(contains(reports[0], what)) << reports[0];
  EXPECT_TRUE(contains(reports[0], "report.kestrel_sanitizer_probe.")) << reports[0];
}

TEST(SanitizerHarness, ChildrenInheritTheReportFolder) {
  const std::filesystem::path dir = child_sanitizer_report_dir();
  ASSERT_FALSE(dir.empty()) << "a sanitizer build's tests must have a report folder";
  EXPECT_TRUE(std::filesystem::is_directory(dir)) << dir;
  const char* options = std::getenv(kOptions);
  ASSERT_NE(options, nullptr) << kOptions;
  EXPECT_TRUE(contains(options, "log_path=" + (dir / "report").string())) << options;
}

TEST(SanitizerHarness, ACleanChildWritesNoReport) {
  const RunResult r = run({probe(), "clean"}, 60.0);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(take_child_sanitizer_reports().empty());
}

TEST(SanitizerHarness, AChildsDefectIsReportedInTheFolder) { expect_one_report(kDefect, kReport); }

#ifdef KESTREL_PROBE_ASAN
TEST(SanitizerHarness, AChildsUndefinedBehaviourIsReportedAndEndsIt) {
  expect_one_report("signed-overflow", "runtime error: signed integer overflow");
}

TEST(SanitizerHarness, AChildsLeakIsReportedAtItsExit) {
  const char* options = std::getenv("ASAN_OPTIONS");
  if (options != nullptr && contains(options, "detect_leaks=0")) GTEST_SKIP() << "ASAN_OPTIONS has detect_leaks=0";
  expect_one_report("leak", "ERROR: LeakSanitizer: detected memory leaks");
}

TEST(SanitizerHarness, AbortOnErrorEndsTheChildWithSigabrt) {
  // ./kestrel test sets abort_on_error=1 (KESTREL_ASAN_OPTIONS), so that a report is a crash.
  const char* options = std::getenv("ASAN_OPTIONS");
  if (options == nullptr || !contains(options, "abort_on_error=1"))
    GTEST_SKIP() << "ASAN_OPTIONS has no abort_on_error=1 (run by ./kestrel test, it has)";
  const RunResult r = run({probe(), "heap-overflow"}, 60.0);
  EXPECT_EQ(r.exit_code, 128 + SIGABRT) << r.err;
  take_child_sanitizer_reports();
}
#endif

// Run in a child by the next test, never on its own (DISABLED_): it leaves the probe's report.
TEST(SanitizerHarnessChild, DISABLED_LeavesAReport) {
  const RunResult r = run({probe(), kDefect}, 60.0);
  EXPECT_NE(r.exit_code, 0);
}

TEST(SanitizerHarness, AReportLeftByATestFailsThatTest) {
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  const RunResult r = run({self, "--gtest_also_run_disabled_tests",
                           "--gtest_filter=SanitizerHarnessChild.DISABLED_LeavesAReport"}, 120.0);
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_TRUE(contains(r.out, "a child process wrote a sanitizer report during this test")) << r.out;
  EXPECT_TRUE(contains(r.out, kReport)) << r.out;
  EXPECT_TRUE(contains(r.out, "[  FAILED  ] SanitizerHarnessChild.DISABLED_LeavesAReport")) << r.out;
  // The grandchild's report went to the child's folder, not to this process's.
  EXPECT_TRUE(take_child_sanitizer_reports().empty());
}

}  // namespace
}  // namespace kestrel::test
