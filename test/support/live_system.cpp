#include "test/support/live_system.h"

#include <dirent.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <lcm/lcm-cpp.hpp>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/transport/channels.h"
#include "common/transport/lcm_url.h"
#include "common/transport/log_file.h"
#include "tools/launch/isolation.h"

namespace kestrel::test {
namespace {

using Clock = std::chrono::steady_clock;

int64_t wall_utime() {
  return std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch())
      .count();
}

int decode_status(int status) {
  if (WIFEXITED(status)) return WEXITSTATUS(status);
  if (WIFSIGNALED(status)) return 128 + WTERMSIG(status);
  return -1;
}

// The processes whose parent is this one: children, and orphans this subreaper adopted.
std::vector<pid_t> children_of_this_process() {
  std::vector<pid_t> out;
  const pid_t self = ::getpid();
  DIR* proc = ::opendir("/proc");
  if (proc == nullptr) return out;
  while (const dirent* e = ::readdir(proc)) {
    char* end = nullptr;
    const long pid = std::strtol(e->d_name, &end, 10);
    if (*end != '\0' || pid <= 0) continue;
    std::ifstream stat("/proc/" + std::string(e->d_name) + "/stat");
    std::string text;  // one line
    std::getline(stat, text);
    const size_t paren = text.rfind(')');  // the name may hold spaces and parentheses
    if (paren == std::string::npos) continue;
    std::istringstream fields(text.substr(paren + 1));
    std::string state;
    long ppid = 0;
    fields >> state >> ppid;
    if (ppid == self) out.push_back(static_cast<pid_t>(pid));
  }
  ::closedir(proc);
  return out;
}

}  // namespace

struct LiveSystem::Listener {
  explicit Listener(const std::string& url) : lcm(url) {}
  lcm::LCM lcm;
  std::optional<transport::LogWriter> recording;
  std::vector<std::string> recorded;  // channels written to `recording`
  std::atomic<bool> stop{false};
  std::thread thread;
  bool finished = false;

  void handle(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    owner->on_message(channel, rbuf->data, rbuf->data_size);
  }
  LiveSystem* owner = nullptr;
};

std::string LiveSystem::isolate() {
  static const std::string why = [] {
    try {
      launch::enter_private_network();
    } catch (const launch::IsolationError& e) {
      return std::string(e.what());
    }
    // Orphans (a launcher's children when it is killed) become this process's, to be reaped.
    ::prctl(PR_SET_CHILD_SUBREAPER, 1, 0, 0, 0);
    return std::string();
  }();
  return why;
}

LiveSystem::LiveSystem(std::filesystem::path dir, Options options)
    : dir_(std::move(dir)), options_(std::move(options)) {
  const std::string why = isolate();
  if (!why.empty()) throw std::runtime_error("LiveSystem without a private network: " + why);
  std::vector<std::string> channels = options_.channels;
  if (std::find(channels.begin(), channels.end(), channel::kProcessStatus) == channels.end())
    channels.push_back(channel::kProcessStatus);
  for (const auto& c : options_.recorded)
    if (std::find(channels.begin(), channels.end(), c) == channels.end())
      throw std::invalid_argument("LiveSystem: channel " + c + " is to be recorded but not subscribed to");
  std::filesystem::create_directories(dir_);
  listener_ = std::make_unique<Listener>(transport::resolve_lcm_url(""));
  if (!listener_->lcm.good()) throw std::runtime_error("LiveSystem: LCM did not start in the private network");
  listener_->owner = this;
  if (!options_.record.empty()) {
    listener_->recording.emplace(options_.record.string());
    listener_->recorded = options_.recorded.empty() ? options_.channels : options_.recorded;
  }
  // No queue limit: LCM drops the oldest messages of a subscription whose queue holds its
  // capacity (30 by default), which a listener starved of CPU reaches within a third of a
  // second of IMU (a CI run lost 170 of 1002 IMU samples so while a build ran beside it), and
  // a test's recording must hold every message that arrived.
  for (const auto& c : channels) listener_->lcm.subscribe(c, &Listener::handle, listener_.get())->setQueueCapacity(0);
  listener_->thread = std::thread([this] { listen(); });
}

LiveSystem::~LiveSystem() {
  // A clean stop first (the processes flush their logs, a launcher stops its own), then SIGKILL.
  for (const auto& label : order_) {
    Child& c = children_.at(label);
    if (!c.status) ::kill(-c.pid, SIGINT);
  }
  const auto deadline = Clock::now() + std::chrono::seconds(5);
  for (const auto& label : order_) {
    Child& c = children_.at(label);
    while (!c.status && Clock::now() < deadline) {
      c.status = reap(c.pid, false);
      if (!c.status) std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    if (!c.status) {
      ::kill(-c.pid, SIGKILL);
      c.status = reap(c.pid, true);
    }
  }
  reap_everything();
  finish();
}

void LiveSystem::reap_everything() {
  // Whatever a child left behind (adopted by this subreaper) goes too.
  for (int round = 0; round < 10; ++round) {
    const std::vector<pid_t> left = children_of_this_process();
    if (left.empty()) return;
    for (pid_t p : left) ::kill(p, SIGKILL);
    for (pid_t p : left) ::waitpid(p, nullptr, 0);
  }
}

void LiveSystem::listen() {
  while (!listener_->stop.load()) listener_->lcm.handleTimeout(50);
  // What the socket already holds is handled before returning: a process's last messages,
  // sent before it exited, are kept.
  while (listener_->lcm.handleTimeout(20) > 0) {
  }
}

void LiveSystem::finish() {
  if (!listener_ || listener_->finished) return;
  listener_->stop.store(true);
  if (listener_->thread.joinable()) listener_->thread.join();
  if (listener_->recording) listener_->recording->close();
  listener_->finished = true;
}

void LiveSystem::on_message(const std::string& channel, const void* data, size_t size) {
  ReceivedMessage m;
  m.channel = channel;
  m.received_utime = wall_utime();
  const auto* bytes = static_cast<const uint8_t*>(data);
  m.data.assign(bytes, bytes + size);
  if (listener_->recording && std::find(listener_->recorded.begin(), listener_->recorded.end(), channel) !=
                                  listener_->recorded.end())
    listener_->recording->write(channel, m.received_utime, m.data);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    messages_.push_back(std::move(m));
  }
  arrived_.notify_all();
}

std::vector<ReceivedMessage> LiveSystem::messages(const std::string& channel) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<ReceivedMessage> out;
  for (const auto& m : messages_)
    if (channel.empty() || m.channel == channel) out.push_back(m);
  return out;
}

size_t LiveSystem::received() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return messages_.size();
}

bool LiveSystem::wait_raw(const std::string& channel, const std::function<bool(const ReceivedMessage&)>& match,
                          double timeout_s, const std::string& what, size_t from) {
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(timeout_s));
  size_t next = from, seen = 0;
  std::unique_lock<std::mutex> lock(mutex_);
  for (;;) {
    while (next < messages_.size()) {
      if (messages_[next].channel != channel) {
        ++next;
        continue;
      }
      // Matched without the lock: the vector may grow meanwhile, so the message is copied.
      const ReceivedMessage m = messages_[next++];
      ++seen;
      lock.unlock();
      const bool ok = match(m);
      lock.lock();
      if (ok) return true;
    }
    if (arrived_.wait_until(lock, deadline) == std::cv_status::timeout && next >= messages_.size()) {
      ADD_FAILURE() << "LiveSystem: waited " << timeout_s << " s for " << what << " on " << channel << "; "
                    << seen << " other message(s) on it came";
      return false;
    }
  }
}

std::optional<kestrel::process_status_t> LiveSystem::wait_for_state(const std::string& name, int8_t state,
                                                                    double timeout_s, size_t from) {
  return wait_for<kestrel::process_status_t>(
      channel::kProcessStatus,
      [&](const kestrel::process_status_t& s) { return s.name == name && s.state == state; }, timeout_s,
      "a heartbeat of " + name + " in state " + std::to_string(state), from);
}

pid_t LiveSystem::wait_running(const std::string& name, double timeout_s, size_t from) {
  const auto s = wait_for_state(name, kestrel::process_status_t::STATE_RUNNING, timeout_s, from);
  return s ? static_cast<pid_t>(s->pid) : 0;
}

pid_t LiveSystem::wait_heartbeat(const std::string& name, double timeout_s, size_t from) {
  const auto s = wait_for<kestrel::process_status_t>(
      channel::kProcessStatus, [&](const kestrel::process_status_t& m) { return m.name == name; }, timeout_s,
      "a heartbeat of " + name, from);
  return s ? static_cast<pid_t>(s->pid) : 0;
}

pid_t LiveSystem::start(const std::string& label, const std::vector<std::string>& argv) {
  if (argv.empty()) throw std::invalid_argument("LiveSystem::start: no program");
  const auto it = children_.find(label);
  if (it != children_.end() && !it->second.status)
    throw std::invalid_argument("LiveSystem::start: " + label + " is still running");
  const std::string log = log_path(label).string();
  std::vector<char*> args;
  for (const auto& a : argv) args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  const pid_t parent = ::getpid();
  const pid_t pid = ::fork();
  if (pid < 0) throw std::runtime_error(std::string("fork failed: ") + std::strerror(errno));
  if (pid == 0) {
    ::setpgid(0, 0);
    // A test process killed outright (a ctest timeout) runs no destructor: its children end
    // with it all the same, as on Ctrl-C.
    ::prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (::getppid() != parent) ::_exit(126);
    const int out = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    const int in = ::open("/dev/null", O_RDONLY);
    if (out < 0 || in < 0) ::_exit(126);
    ::dup2(in, 0);
    ::dup2(out, 1);
    ::dup2(out, 2);
    ::close_range(3, ~0U, 0);  // not the test's LCM sockets
    ::execvp(args[0], args.data());
    const std::string why = std::string("exec ") + args[0] + ": " + std::strerror(errno) + "\n";
    (void)!::write(2, why.data(), why.size());
    ::_exit(127);
  }
  ::setpgid(pid, pid);  // also here, so that kill() finds the group at once
  children_[label] = Child{pid, std::nullopt};
  order_.erase(std::remove(order_.begin(), order_.end(), label), order_.end());
  order_.push_back(label);
  return pid;
}

pid_t LiveSystem::pid(const std::string& label) const {
  const auto it = children_.find(label);
  return it == children_.end() ? 0 : it->second.pid;
}

LiveSystem::Child& LiveSystem::child(const std::string& label) {
  const auto it = children_.find(label);
  if (it == children_.end()) throw std::invalid_argument("LiveSystem: no child " + label);
  return it->second;
}

void LiveSystem::kill(const std::string& label, int signal) {
  Child& c = child(label);
  if (!c.status) ::kill(-c.pid, signal);
}

void LiveSystem::kill_pid(pid_t pid, int signal) {
  if (pid > 0) ::kill(pid, signal);
}

std::optional<int> LiveSystem::reap(pid_t pid, bool block) {
  int status = 0;
  for (;;) {
    const pid_t r = ::waitpid(pid, &status, block ? 0 : WNOHANG);
    if (r == pid) return decode_status(status);
    if (r == 0) return std::nullopt;
    if (errno != EINTR) return -1;  // not our child any more: nothing to wait for
  }
}

std::optional<int> LiveSystem::wait_exit(const std::string& label, double timeout_s) {
  Child& c = child(label);
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(timeout_s));
  while (!c.status) {
    c.status = reap(c.pid, false);
    if (c.status || Clock::now() >= deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return c.status;
}

int LiveSystem::exit_status(const std::string& label, double timeout_s) {
  const std::optional<int> status = wait_exit(label, timeout_s);
  if (status) return *status;
  ADD_FAILURE() << "LiveSystem: " << label << " (pid " << pid(label) << ") still runs after " << timeout_s
                << " s; its log:\n" << output(label);
  return -1;
}

int LiveSystem::stop(const std::string& label, int signal, double timeout_s) {
  kill(label, signal);
  return exit_status(label, timeout_s);
}

void LiveSystem::stop_all(int signal, double timeout_s) {
  for (const auto& label : order_) kill(label, signal);
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(timeout_s));
  for (const auto& label : order_) {
    const double left = std::chrono::duration<double>(deadline - Clock::now()).count();
    exit_status(label, std::max(0.0, left));
  }
}

int LiveSystem::run(const std::string& label, const std::vector<std::string>& argv, double timeout_s) {
  start(label, argv);
  return exit_status(label, timeout_s);
}

int LiveSystem::replay(const std::filesystem::path& log, const std::string& expect, const std::filesystem::path& record,
                       const std::vector<std::string>& extra, double timeout_s) {
  std::vector<std::string> argv = {tool("replay").string(), log.string(), "--expect", expect, "--record",
                                   record.string()};
  argv.insert(argv.end(), extra.begin(), extra.end());
  return run("replay", argv, timeout_s);
}

}  // namespace kestrel::test
