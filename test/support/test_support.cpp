#include "test/support/test_support.h"

#include "common/error.h"

#include <fcntl.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cstdio>
#include <chrono>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <random>

#include "common/transport/lcm_url.h"

namespace kestrel::test {

// ---- Sanitizer reports of child processes -------------------------------------------------
//
// In a sanitizer build the tools a test runs are sanitized too, and a report ends the child
// with a signal (abort_on_error) or an exit code — which a test that expects a crash, kills the
// child, or ignores a background child's status would not notice. So each test process sends its
// children's reports to files of its own (log_path, in the options every child inherits) and
// fails the test during which one appears, quoting it (ChildReports below). The test
// process's own reports still go to stderr: its runtime read its options before this runs.
#if defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer)
#define KESTREL_TEST_SANITIZED 1
#endif
#endif
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define KESTREL_TEST_SANITIZED 1
#endif

namespace {

#ifdef KESTREL_TEST_SANITIZED
constexpr bool kSanitized = true;
#else
constexpr bool kSanitized = false;
#endif

std::string joined(const std::vector<std::string>& reports) {
  std::string all;
  for (const auto& r : reports) all += "\n" + r;
  return all;
}

class ChildReports {
 public:
  static ChildReports& instance() {
    static ChildReports reports;
    return reports;
  }

  const std::filesystem::path& dir() const { return dir_; }

  /// The reports written since the last call, each as "<file>:\n<text>".
  std::vector<std::string> take_new() {
    std::vector<std::string> found;
    std::error_code ec;
    if (dir_.empty() || !std::filesystem::is_directory(dir_, ec)) return found;
    std::vector<std::filesystem::path> files;
    for (const auto& entry : std::filesystem::directory_iterator(dir_, ec)) files.push_back(entry.path());
    std::sort(files.begin(), files.end());
    for (const auto& file : files) {
      if (std::find(seen_.begin(), seen_.end(), file) != seen_.end()) continue;
      seen_.push_back(file);
      found.push_back(file.string() + ":\n" + read_file(file));
    }
    return found;
  }

  ~ChildReports() {
    // At exit, in the process that made the folder (not in a forked child): a report no test
    // saw (a child that outlived the tests) still fails the run. The reports were quoted by
    // the failures they caused, so the folder goes.
    if (dir_.empty() || ::getpid() != owner_) return;
    const auto late = take_new();
    std::error_code ec;
    std::filesystem::remove_all(dir_, ec);
    if (!late.empty()) {
      std::fprintf(stderr, "test support: a child process wrote a sanitizer report after the tests ended:%s\n",
                   joined(late).c_str());
      std::_Exit(1);
    }
  }

 private:
  ChildReports() {
    if (!kSanitized) return;
    std::error_code ec;
    const auto dir = std::filesystem::temp_directory_path(ec) /
                     ("kestrel-sanitizer-reports-" + std::to_string(::getpid()));
    if (ec || !(std::filesystem::create_directory(dir, ec) || std::filesystem::is_directory(dir, ec))) {
      std::fprintf(stderr, "test support: cannot create %s: child processes' sanitizer reports go to stderr\n",
                   dir.c_str());
      return;
    }
    dir_ = dir;
    owner_ = ::getpid();
    // Later flags win: a child's reports go to <dir>/report.<its executable>.<its pid>.
    const std::string where = ":log_path=" + (dir / "report").string() + ":log_exe_name=1";
    for (const char* name : {"ASAN_OPTIONS", "UBSAN_OPTIONS", "LSAN_OPTIONS", "TSAN_OPTIONS"}) {
      const char* old = std::getenv(name);
      ::setenv(name, ((old != nullptr ? std::string(old) : std::string()) + where).c_str(), 1);
    }
  }

  std::filesystem::path dir_;
  pid_t owner_ = 0;
  std::vector<std::filesystem::path> seen_;
};

// Fails the test during which a child's report appeared.
class ChildReportListener : public ::testing::EmptyTestEventListener {
  void OnTestEnd(const ::testing::TestInfo&) override {
    const auto reports = ChildReports::instance().take_new();
    EXPECT_TRUE(reports.empty()) << "a child process wrote a sanitizer report during this test:"
                                 << joined(reports);
  }
};

// Fails the run on a report that appeared after the last test ended (a child still exiting).
class ChildReportEnvironment : public ::testing::Environment {
  void TearDown() override {
    const auto reports = ChildReports::instance().take_new();
    EXPECT_TRUE(reports.empty()) << "a child process wrote a sanitizer report after the last test:"
                                 << joined(reports);
  }
};

// Before main: the options are set before any test starts a child (or a thread).
[[maybe_unused]] const bool g_child_reports_watched = [] {
  if (!kSanitized || ChildReports::instance().dir().empty()) return false;
  ::testing::UnitTest::GetInstance()->listeners().Append(new ChildReportListener);
  ::testing::AddGlobalTestEnvironment(new ChildReportEnvironment);
  return true;
}();

}  // namespace

std::filesystem::path child_sanitizer_report_dir() { return ChildReports::instance().dir(); }

std::vector<std::string> take_child_sanitizer_reports() { return ChildReports::instance().take_new(); }

std::string input_error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no InputError)";
}

std::filesystem::path shared_data() {
  std::filesystem::path p = KESTREL_SHARED_DATA;
  if (const char* env = std::getenv("KESTREL_SHARED_DATA"); env && *env) p = env;
  std::error_code ec;
  return std::filesystem::is_directory(p, ec) ? std::filesystem::canonical(p) : std::filesystem::path();
}

std::filesystem::path tum_sequence(const std::string& name) {
  const auto root = shared_data();
  if (root.empty()) return {};
  const auto p = root / "tum" / name;
  std::error_code ec;
  return std::filesystem::is_regular_file(p / "rgb.txt", ec) ? p : std::filesystem::path();
}

std::filesystem::path tool(const std::string& name) {
  return std::filesystem::path(KESTREL_BINARY_DIR) / "bin" / ("kestrel-" + name);
}

std::filesystem::path source_dir() { return std::filesystem::path(KESTREL_SOURCE_DIR); }

std::string read_file(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream all;
  all << in.rdbuf();
  return all.str();
}

TempDir::TempDir() {
  std::random_device rd;
  const auto base = std::filesystem::temp_directory_path();
  for (int attempt = 0; attempt < 100; ++attempt) {
    auto p = base / ("kestrel-test-" + std::to_string(rd()));
    if (std::filesystem::create_directory(p)) {
      path_ = p;
      return;
    }
  }
  throw std::runtime_error("cannot create a temporary folder");
}

TempDir::~TempDir() {
  if (::testing::Test::HasFailure()) {
    // A system test's only account of a rare failure is what its processes wrote here.
    std::fprintf(stderr, "kept %s: the test failed\n", path_.c_str());
    return;
  }
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

RunResult run(const std::vector<std::string>& argv, double timeout_s) {
  RunResult result;
  int out_pipe[2], err_pipe[2];
  if (pipe(out_pipe) != 0 || pipe(err_pipe) != 0) throw std::runtime_error("pipe failed");
  const pid_t pid = fork();
  if (pid < 0) throw std::runtime_error("fork failed");
  if (pid == 0) {
    setpgid(0, 0);
    dup2(out_pipe[1], 1);
    dup2(err_pipe[1], 2);
    close(out_pipe[0]);
    close(err_pipe[0]);
    std::vector<char*> args;
    for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
    args.push_back(nullptr);
    execvp(args[0], args.data());
    _exit(127);
  }
  close(out_pipe[1]);
  close(err_pipe[1]);
  const auto deadline =
      std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  std::array<pollfd, 2> fds{{{out_pipe[0], POLLIN, 0}, {err_pipe[0], POLLIN, 0}}};
  int open_fds = 2;
  bool timed_out = false;
  char buf[65536];
  while (open_fds > 0) {
    const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(
        deadline - std::chrono::steady_clock::now());
    if (left.count() <= 0) {
      timed_out = true;
      break;
    }
    if (poll(fds.data(), fds.size(), static_cast<int>(left.count())) <= 0) continue;
    for (int i = 0; i < 2; ++i) {
      if (fds[i].fd < 0 || !(fds[i].revents & (POLLIN | POLLHUP))) continue;
      const ssize_t n = read(fds[i].fd, buf, sizeof buf);
      if (n <= 0) {
        close(fds[i].fd);
        fds[i].fd = -1;
        --open_fds;
      } else {
        (i == 0 ? result.out : result.err).append(buf, static_cast<size_t>(n));
      }
    }
  }
  if (timed_out) kill(-pid, SIGKILL);
  for (auto& f : fds)
    if (f.fd >= 0) close(f.fd);
  int status = 0;
  waitpid(pid, &status, 0);
  if (timed_out) {
    result.exit_code = -1;
    result.err += "\n[test harness: killed after " + std::to_string(timeout_s) + " s]";
  } else if (WIFEXITED(status)) {
    result.exit_code = WEXITSTATUS(status);
  } else if (WIFSIGNALED(status)) {
    result.exit_code = 128 + WTERMSIG(status);
  }
  return result;
}

std::string wait_for_lcm_listener_sh(double timeout_s) {
  // The port of udpm://group:port?..., as /proc/net/udp lists a local address (hex, upper case).
  const std::string url = transport::kDefaultLcmUrl;
  const size_t colon = url.find(':', url.find("//") + 2), end = url.find('?', colon);
  char port[8];
  std::snprintf(port, sizeof port, "%04X", std::stoi(url.substr(colon + 1, end - colon - 1)));
  const int tries = std::max(1, static_cast<int>(timeout_s / 0.05));
  return std::string("{ i=0; until grep -q ':") + port + " ' /proc/net/udp; do i=$((i+1)); [ $i -ge " +
         std::to_string(tries) + " ] && exit 98; sleep 0.05; done; }";
}

bool can_isolate_network() {
  const RunResult r = run({"unshare", "-n", "true"}, 10.0);
  if (r.exit_code == 0) return true;
  return run({"unshare", "-rn", "true"}, 10.0).exit_code == 0;
}

RunResult run_isolated(const std::string& script, double timeout_s) {
  return run({tool("isolated").string(), "--", "sh", "-c", script}, timeout_s);
}

std::string quoted(const std::string& s) {
  std::string q = "'";
  for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return q + "'";
}

}  // namespace kestrel::test
