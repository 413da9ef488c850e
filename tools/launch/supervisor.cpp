#include "tools/launch/supervisor.h"

#include <fcntl.h>
#include <sched.h>
#include <signal.h>
#include <cstring>
#include <sys/prctl.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "common/error.h"

namespace kestrel::launch {

std::string log_tail(const std::filesystem::path& log, size_t lines) {
  std::ifstream in(log);
  std::vector<std::string> all;
  for (std::string l; std::getline(in, l);) all.push_back(l);
  std::string out;
  for (size_t i = all.size() > lines ? all.size() - lines : 0; i < all.size(); ++i)
    out += (out.empty() ? "    | " : "\n    | ") + all[i];
  return out;
}

Ending describe_wait_status(int wait_status) {
  if (WIFEXITED(wait_status)) {
    const int code = WEXITSTATUS(wait_status);
    return {code, "exited with status " + std::to_string(code)};
  }
  if (WIFSIGNALED(wait_status)) {
    const int sig = WTERMSIG(wait_status);
    const char* abbrev = sigabbrev_np(sig);
    return {128 + sig, std::string("killed by SIG") + (abbrev ? abbrev : std::to_string(sig).c_str())};
  }
  return {1, "ended (wait status " + std::to_string(wait_status) + ")"};
}

std::optional<double> process_cpu_seconds(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/stat");
  std::string stat;
  if (!std::getline(in, stat)) return std::nullopt;
  // "pid (comm) state ppid ...": comm may hold spaces and parentheses, so fields are counted
  // after its last ')'; utime, stime, cutime and cstime are fields 14 to 17 (proc(5)), in
  // clock ticks.
  const size_t close = stat.rfind(')');
  if (close == std::string::npos) return std::nullopt;
  std::istringstream fields(stat.substr(close + 1));
  std::string field;
  double ticks = 0.0;
  for (int i = 3; i <= 17 && fields >> field; ++i)
    if (i >= 14) ticks += std::strtod(field.c_str(), nullptr);
  if (!fields) return std::nullopt;
  const long per_second = ::sysconf(_SC_CLK_TCK);
  return per_second > 0 ? ticks / static_cast<double>(per_second) : std::optional<double>{};
}

Supervisor::Supervisor(const ProcessSet& set, const std::vector<std::filesystem::path>& executables,
                       SupervisorOptions options)
    : options_(std::move(options)) {
  if (set.size() != executables.size()) throw std::invalid_argument("one executable per process");
  std::filesystem::create_directories(options_.log_dir);
  for (size_t i = 0; i < set.size(); ++i) {
    Child child;
    child.spec = set[i];
    child.executable = executables[i];
    child.log = options_.log_dir / (set[i].name + ".log");
    children_.push_back(std::move(child));
  }
}

Supervisor::~Supervisor() { stop_all(); }

ChildEvent Supervisor::start(Child& child) {
  // Everything the child needs is prepared before fork(): after it, only async-signal-safe
  // calls are allowed (the launcher has an LCM thread).
  // A restart adds the process's restart_args (process_set.h).
  std::vector<std::string> args = command_of_start(child.spec, child.restarts);
  args[0] = child.executable.string();
  std::vector<char*> argv;
  for (auto& a : args) argv.push_back(a.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_strings;
  for (char** e = environ; *e; ++e) env_strings.emplace_back(*e);
  env_strings.insert(env_strings.end(), options_.environment.begin(), options_.environment.end());
  std::vector<char*> envp;
  for (auto& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);
  // in-place: a process's log, appended
  const int log_fd = ::open(child.log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (log_fd < 0) throw std::runtime_error(child.log.string() + ": " + std::strerror(errno));
  const pid_t launcher = ::getpid();
  const auto netns = options_.netns_by_side.find(child.spec.side);
  const int netns_fd = netns == options_.netns_by_side.end() ? -1 : netns->second;

  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(log_fd);
    throw std::runtime_error(std::string("fork: ") + std::strerror(errno));
  }
  if (pid == 0) {
    ::setpgid(0, 0);
    ::signal(SIGINT, SIG_DFL);
    ::signal(SIGTERM, SIG_DFL);
    sigset_t none;
    sigemptyset(&none);
    ::sigprocmask(SIG_SETMASK, &none, nullptr);
    // Die with the launcher however it dies, kill -9 included: in its own process group the
    // child is out of reach of the launcher's group, so only the kernel can tell it. SIGTERM,
    // not SIGKILL, so that a process ends as it does on Ctrl-C, closing its files. Set only
    // once SIGTERM is back at its default, so that the launcher's inherited handler cannot
    // swallow it. If the launcher died before the prctl, the signal never comes (we were
    // reparented already): end now.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != launcher) ::_exit(kExitFailure);
    ::dup2(log_fd, STDOUT_FILENO);
    ::dup2(log_fd, STDERR_FILENO);
    if (netns_fd >= 0 && ::setns(netns_fd, CLONE_NEWNET) != 0) {
      const char msg[] = "kestrel launch: cannot enter the side's network namespace\n";
      [[maybe_unused]] auto n = ::write(STDERR_FILENO, msg, sizeof msg - 1);
      ::_exit(kExitUnavailable);
    }
    const int devnull = ::open("/dev/null", O_RDONLY);
    if (devnull >= 0) ::dup2(devnull, STDIN_FILENO);
    ::execve(argv[0], argv.data(), envp.data());
    const char msg[] = "kestrel launch: exec failed\n";
    [[maybe_unused]] auto n = ::write(STDERR_FILENO, msg, sizeof msg - 1);
    ::_exit(127);
  }
  ::setpgid(pid, pid);  // also here, so the group exists before we might signal it
  ::close(log_fd);
  child.pid = pid;
  child.restart_at.reset();
  return {ChildEvent::kStarted, child.spec.name, pid, {}};
}

std::vector<ChildEvent> Supervisor::start_all(const std::string& except) {
  std::vector<ChildEvent> events;
  for (auto& c : children_)
    if (c.pid < 0 && c.spec.name != except) events.push_back(start(c));
  return events;
}

std::optional<ChildEvent> Supervisor::reap(Child& child, bool block) {
  if (child.pid < 0) return std::nullopt;
  int status = 0;
  struct rusage usage {};
  const pid_t r = ::wait4(child.pid, &status, block ? 0 : WNOHANG, &usage);
  if (r == 0) return std::nullopt;
  if (r < 0 && errno == EINTR) return std::nullopt;
  const pid_t pid = child.pid;
  child.pid = -1;
  child.last_ending = r < 0 ? Ending{1, "vanished"} : describe_wait_status(status);
  child.last_ending->at = Clock::now();
  if (r > 0) {
    auto seconds = [](const timeval& t) { return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec); };
    child.last_ending->cpu_s = seconds(usage.ru_utime) + seconds(usage.ru_stime);
  }
  ::kill(-pid, SIGKILL);  // anything it left behind in its group
  return ChildEvent{ChildEvent::kEnded, child.spec.name, pid, *child.last_ending};
}

std::vector<ChildEvent> Supervisor::poll(Clock::time_point now) {
  std::vector<ChildEvent> events;
  for (auto& c : children_) {
    if (auto e = reap(c, false)) {
      events.push_back(*e);
      if (!options_.restart) continue;
      if (c.restarts >= options_.max_restarts) {
        events.push_back({ChildEvent::kGaveUp, c.spec.name, e->pid, e->ending});
        continue;
      }
      c.restart_at = now + std::chrono::duration_cast<Clock::duration>(
                               std::chrono::duration<double>(options_.restart_delay_s));
      events.push_back({ChildEvent::kRestarting, c.spec.name, e->pid, e->ending});
    }
    if (c.pid < 0 && c.restart_at && now >= *c.restart_at) {
      ++c.restarts;
      events.push_back(start(c));
    }
  }
  return events;
}

std::vector<ChildEvent> Supervisor::stop_all() {
  std::vector<ChildEvent> events;
  for (auto it = children_.rbegin(); it != children_.rend(); ++it) {
    it->restart_at.reset();
    if (it->pid > 0) ::kill(-it->pid, SIGTERM);
  }
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(options_.stop_timeout_s));
  while (running() > 0 && Clock::now() < deadline) {
    for (auto& c : children_)
      if (auto e = reap(c, false)) events.push_back(*e);
    if (running() > 0) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  for (auto& c : children_) {
    if (c.pid > 0) ::kill(-c.pid, SIGKILL);
    if (auto e = reap(c, true)) events.push_back(*e);
  }
  return events;
}

const Supervisor::Child* Supervisor::find(pid_t pid) const {
  for (const auto& c : children_)
    if (c.pid == pid) return &c;
  return nullptr;
}

const Supervisor::Child* Supervisor::find(const std::string& name) const {
  for (const auto& c : children_)
    if (c.spec.name == name) return &c;
  return nullptr;
}

size_t Supervisor::running() const {
  size_t n = 0;
  for (const auto& c : children_) n += c.pid > 0;
  return n;
}

}  // namespace kestrel::launch
