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
