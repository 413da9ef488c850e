// kestrel-launch SET: starts the onboard, offboard or all processes of kestrel (process sets in
// tools/launch/processes.yaml), shows their health from their heartbeats, reports a process
// that dies (and restarts it with --restart), and stops them all on Ctrl-C or SIGTERM. With
// --source the set is fed by one more process (a driver or a replay) and the launch ends when
// that process ends.

#include <fmt/chrono.h>
#include <fmt/ranges.h>
#include <poll.h>
#include <sched.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <memory>
#include <optional>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <string>
#include <vector>

#include "common/interrupt.h"
#include "common/cli.h"
#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/lcm_url.h"
#include "common/transport/message.h"
#include "tools/launch/health.h"
#include "tools/launch/isolation.h"
#include "tools/launch/process_set.h"
#include "tools/launch/supervisor.h"

namespace {

namespace fs = std::filesystem;
using namespace kestrel::launch;
using Clock = std::chrono::steady_clock;

// Stands for the offboard namespace in the link's command until the launch has made it.
const char* const kOffboardNetns = "{offboard_netns}";

struct Options {
  std::string set;
  std::string sets_file = KESTREL_DEFAULT_PROCESS_SETS;
  std::vector<std::string> only, without;
  std::string source;
  std::string lcm_url;
  bool isolated = false;
  bool link = false;
  std::string link_options;
  double link_frame_rate = 10;
  bool restart = false;
  int max_restarts = 5;
  std::string log_dir;
  double status_period_s = 10.0;
  bool list = false;
  std::string map;  // a building's saved map (slam.map, mapper.journal)
  double await_map_s = 30.0;
  bool localize_only = false;
  bool no_map_update = false;
};

// LCM 1.3 takes member functions, not lambdas.
struct HeartbeatListener {
  HealthBoard* board;
  void handle(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    try {
      board->heartbeat(kestrel::transport::decode_message<kestrel::process_status_t>(
                           rbuf->data, rbuf->data_size, channel),
                       Clock::now());
    } catch (const kestrel::InputError& e) {
      spdlog::warn("{}", e.what());
    }
  }
};

struct RejectionsListener {
  HealthBoard* board;
  void handle(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    try {
      board->rejections(kestrel::transport::decode_message<kestrel::rejection_counts_t>(rbuf->data, rbuf->data_size,
                                                                                       channel));
    } catch (const kestrel::InputError& e) {
      spdlog::warn("{}", e.what());
    }
  }
};

int launch(const Options& o) {
  const ProcessSet declared = read_process_sets(o.sets_file);  // a bad file: InputError, exit 3
  ProcessSet set;
  try {
    set = select(declared, o.set, o.only, o.without);
  } catch (const kestrel::InputError& e) {  // a name on the command line, not in the file: usage
    throw CLI::ValidationError("--only/--without", e.what());
  }
  // One side alone: the other may have run for a while (a SLAM with a map), so every process
  // starts as a restarted one would (its restart_args: the estimator awaits SLAM's world).
  if (o.set != "all") set = joining_a_running_system(std::move(set));
  if (o.link) {
    // The link first, so that it hears the first messages; the codec onboard, so that frames
    // cross compressed (the link carries CAMERA_RGBD_Z up as CAMERA_RGBD).
    if (o.set != "all") throw CLI::ValidationError("--link", "joins onboard and offboard: use it with the set all");
    std::vector<std::string> link_argv = {"link", "--offboard-netns", kOffboardNetns, "--stats", "{log_dir}/link.json"};
    for (auto& a : split_command(o.link_options)) link_argv.push_back(std::move(a));
    set.insert(set.begin(), {{"link", link_argv, "link"}, {"rgbd-codec", {"rgbd-codec", "--max-rate", fmt::format("{:g}", o.link_frame_rate)}, "onboard"}});
  }
  if (!o.map.empty()) {
    const bool exists = fs::is_regular_file(fs::path(o.map) / "slam.map");
    std::error_code ec;
    fs::create_directories(o.map, ec);  // the mapper's journal goes there from the start
    if (ec) throw kestrel::InputError(o.map + ": cannot make the map's folder (" + ec.message() + ")");
    set = with_saved_map(std::move(set), o.map, exists, {o.await_map_s, o.localize_only, !o.no_map_update});
    spdlog::info("{}: {}", o.map, exists ? "flying in its saved map (SLAM relocalises the vehicle in it), saved again on exit"
                                         : "no map yet: this flight's is saved there on exit");
  }
  if (!o.source.empty()) {
    set.push_back({"source", split_command(o.source), "source"});
  }
  if (set.empty()) throw CLI::ValidationError("SET", "selects no process");
  const fs::path tool_dir = fs::canonical("/proc/self/exe").parent_path();
  std::vector<fs::path> executables;
  for (const auto& p : set) executables.push_back(resolve_executable(p.argv[0], tool_dir));
  if (o.list) {
    for (size_t i = 0; i < set.size(); ++i) {
      std::string args;
      for (size_t k = 1; k < set[i].argv.size(); ++k) args += " " + set[i].argv[k];
      fmt::print("{:<12} {:<9} {}{}\n", set[i].name, set[i].side, executables[i].string(), args);
    }
    return kestrel::kExitOk;
  }

  // Before any thread exists: a network namespace applies to the calling thread only.
  std::optional<PrivateNetworkPair> sides;
  if (o.link) {
    try {
      sides = enter_private_network_pair();
      spdlog::info("private networks: onboard and offboard, each a {}, joined by kestrel-link",
                   to_string(sides->method));
    } catch (const IsolationError& e) {
      spdlog::error("{}", e.what());
      return kestrel::kExitUnavailable;
    }
  } else if (o.isolated) {
    try {
      spdlog::info("private network: {}", to_string(enter_private_network()));
    } catch (const IsolationError& e) {
      spdlog::error("{}", e.what());
      return kestrel::kExitUnavailable;
    }
  }
  const std::string url = kestrel::transport::resolve_lcm_url(o.lcm_url);
  HealthBoard board;
  HeartbeatListener listener{&board};
  RejectionsListener rejections_listener{&board};
  // One LCM per side with --link (each opens its sockets in the namespace it is made and
  // subscribed in), else one.
  std::vector<std::unique_ptr<lcm::LCM>> lcms;
  for (int netns : sides ? std::vector<int>{sides->onboard_fd, sides->offboard_fd} : std::vector<int>{-1}) {
    if (netns >= 0 && ::setns(netns, CLONE_NEWNET) != 0) {
      spdlog::error("cannot enter a side's network namespace: {}", std::strerror(errno));
      return kestrel::kExitUnavailable;
    }
    lcms.push_back(std::make_unique<lcm::LCM>(url));
    if (!lcms.back()->good()) {
      spdlog::error("cannot open LCM at {}", url);
      return kestrel::kExitUnavailable;
    }
    lcms.back()->subscribe(kestrel::channel::kProcessStatus, &HeartbeatListener::handle, &listener);
    lcms.back()->subscribe(kestrel::channel::kProcessRejections, &RejectionsListener::handle, &rejections_listener);
  }

  SupervisorOptions so;
  so.log_dir = o.log_dir.empty() ? fs::temp_directory_path() / ("kestrel-launch-" + std::to_string(::getpid()))
                                 : fs::path(o.log_dir);
  so.environment = {"LCM_DEFAULT_URL=" + url};
  so.restart = o.restart;
  so.max_restarts = o.max_restarts;
  // This launch's own folder (its start time and pid), so that a log folder given again does
  // not hand a new launch the journal of an earlier one.
  const fs::path run_dir = so.log_dir / fmt::format("run-{:%Y%m%dT%H%M%S}-{}", fmt::gmtime(std::time(nullptr)), ::getpid());
  if (names_run_dir(set)) fs::create_directories(run_dir);
  set = with_run_dir(std::move(set), run_dir);
  if (sides) {
    so.netns_by_side = {{"onboard", sides->onboard_fd}, {"source", sides->onboard_fd},
                        {"link", sides->onboard_fd}, {"offboard", sides->offboard_fd}};
    const std::string offboard = "/proc/" + std::to_string(::getpid()) + "/fd/" + std::to_string(sides->offboard_fd);
    for (auto& p : set)
      for (auto& a : p.argv) {
        if (a == kOffboardNetns) a = offboard;
        if (a.rfind("{log_dir}", 0) == 0) a = (so.log_dir / a.substr(10)).string();
      }
  }
  Supervisor supervisor(set, executables, so);

  const auto& interrupted = kestrel::catch_interrupts();

  spdlog::info("{} process{} on {}; logs in {}", set.size(), set.size() == 1 ? "" : "es", url,
               so.log_dir.string());
  bool unexpected_end = false;
  std::optional<Ending> source_ending;
  auto report = [&](const std::vector<ChildEvent>& events, bool stopping) {
    for (const auto& e : events) {
      const auto* child = supervisor.find(e.name);
      switch (e.kind) {
        case ChildEvent::kStarted:
          spdlog::info("started {} (pid {})", e.name, e.pid);
          board.started(e.name, e.pid, Clock::now(), /*heartbeats=*/e.name != "source" && e.name != "link");
          break;
        case ChildEvent::kEnded:
          board.ended(e.name, e.ending.description, e.ending.at, e.ending.cpu_s);
          if (e.name == "source" && !stopping) {
            source_ending = e.ending;
            spdlog::info("the source {}", e.ending.description);
          } else if (!stopping) {
            unexpected_end |= !so.restart;  // a restarted process fails the launch only once it is given up
            spdlog::error("{} (pid {}) {}; last lines of {}:\n{}", e.name, e.pid,
                          e.ending.description, child->log.string(), log_tail(child->log, 5));
          }
          break;
        case ChildEvent::kRestarting:
          // The source's end ends the launch (above), so it is never started again.
          if (e.name != "source") spdlog::warn("restarting {} in {:.1f} s", e.name, so.restart_delay_s);
          break;
        case ChildEvent::kGaveUp:
          unexpected_end = true;
          spdlog::error("{} keeps failing: not restarted again ({} restarts)", e.name, so.max_restarts);
          break;
      }
    }
  };

  // Consumers first; the source once each has sent its first heartbeat (its subscriptions
  // are made by then), so that nothing it sends is lost to a process still starting.
  constexpr const char* kSource = "source";
  report(supervisor.start_all(kSource), false);
  const bool has_source = supervisor.find(kSource) != nullptr;
  bool source_started = !has_source;
  const auto source_deadline = Clock::now() + std::chrono::seconds(15);
  auto next_status = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                        std::chrono::duration<double>(o.status_period_s));
  bool announced_healthy = false;
  while (!interrupted && !source_ending) {
    std::vector<pollfd> fds;
    for (const auto& l : lcms) fds.push_back({l->getFileno(), POLLIN, 0});
    if (::poll(fds.data(), fds.size(), 100) > 0)
      for (size_t i = 0; i < fds.size(); ++i)
        if (fds[i].revents & POLLIN) lcms[i]->handle();
    report(supervisor.poll(), false);
    const auto now = Clock::now();
    if (!source_started) {
      const auto waiting = board.not_yet_heard();
      if (waiting.empty() || now >= source_deadline) {
        if (!waiting.empty())
          spdlog::warn("starting the source although {} has sent no heartbeat in 15 s", fmt::join(waiting, ", "));
        report(supervisor.start_all(), false);
        source_started = true;
      }
    }
    if (!announced_healthy && board.all_running(now)) {
      announced_healthy = true;
      spdlog::info("all processes running");
    }
    if (o.status_period_s > 0 && now >= next_status) {
      next_status = now + std::chrono::duration_cast<Clock::duration>(
                              std::chrono::duration<double>(o.status_period_s));
      for (const auto& c : supervisor.children())
        if (c.pid > 0)
          if (const auto cpu = process_cpu_seconds(c.pid)) board.cpu(c.spec.name, *cpu);
      fmt::print("{}", board.table(now));
      std::fflush(stdout);
    }
    const bool restart_pending = std::any_of(supervisor.children().begin(), supervisor.children().end(),
                                             [](const auto& c) { return c.restart_at.has_value(); });
    if (supervisor.running() == 0 && !restart_pending) {
      spdlog::error("every process has ended");
      break;
    }
  }
  if (interrupted) spdlog::info("stopping on SIG{}", sigabbrev_np(kestrel::interrupt_signal()));
  report(supervisor.stop_all(), true);
  // Each process's last heartbeat and rejection counts, sent as it stopped, are still queued.
  for (bool any = true; any;) {
    any = false;
    for (const auto& l : lcms) {
      pollfd fd{l->getFileno(), POLLIN, 0};
      if (::poll(&fd, 1, 0) > 0 && (fd.revents & POLLIN)) {
        l->handle();
        any = true;
      }
    }
  }
  fmt::print("{}", board.table(Clock::now()));
  if (const std::string rejected = board.rejections_table(); !rejected.empty()) fmt::print("\n{}", rejected);
  if (kestrel::interrupt_signal() == SIGINT) return kestrel::kExitInterrupted;
  if (source_ending) return source_ending->code == 0 && !unexpected_end ? kestrel::kExitOk : kestrel::kExitFailure;
  return unexpected_end ? kestrel::kExitFailure : kestrel::kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app(
      "launch",
      "Starts a kestrel process set (onboard, offboard or all), shows each process's health "
      "from its heartbeats, reports a process that dies with its exit status, and stops them "
      "all on Ctrl-C/SIGTERM. Exit: 0 clean stop or the source finished well; 1 a process "
      "died or the source failed; 2 usage; 3 bad process-set file; 4 no network; 130 Ctrl-C.");
  Options o;
  app.add_option("set", o.set, "onboard, offboard or all")
      ->required()
      ->check(CLI::IsMember({"onboard", "offboard", "all"}));
  app.add_option("--sets", o.sets_file, "Process-set file (YAML)")->capture_default_str();
  app.add_option("--only", o.only, "Start only these processes of the set (a,b)")->delimiter(',');
  app.add_option("--without", o.without, "Leave these processes out (a,b)")->delimiter(',');
  app.add_option("--source", o.source,
                 "One more process that feeds the set, e.g. \"sim --world room\" or \"replay "
                 "LOG --record out.lcmlog\"; started last, and the launch ends when it ends");
  app.add_option("--lcm-url", o.lcm_url, "LCM URL for the launcher and every process "
                                         "(default: $LCM_DEFAULT_URL or kestrel's)");
  app.add_flag("--isolated", o.isolated,
               "Run the set in a private network namespace with multicast on loopback");
  app.add_flag("--link", o.link,
               "Run onboard (with the source) and offboard in two private networks joined by "
               "kestrel-link, an emulated Wi-Fi link; frames cross compressed (rgbd-codec)");
  app.add_option("--link-options", o.link_options,
                 "Options of kestrel-link, e.g. \"--loss 10 --delay 30 --jitter 10 --rate 20 --seed 1\"");
  app.add_option("--link-frame-rate", o.link_frame_rate,
                 "--link: frames per second that cross, compressed (rgbd-codec --max-rate; 0: all)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_flag("--restart", o.restart, "Restart a process that dies");
  app.add_option("--max-restarts", o.max_restarts, "Give up on a process after this many restarts")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  app.add_option("--log-dir", o.log_dir, "Folder for the processes' logs (default: a new one in $TMPDIR)");
  app.add_option("--status-period", o.status_period_s, "Seconds between health tables (0: none)")
      ->capture_default_str()
      ->check(CLI::NonNegativeNumber);
  CLI::Option* map_option = app.add_option("--map", o.map,
                 "A building's map folder: SLAM starts from the map saved there (relocalising the vehicle; the "
                 "estimator awaits the map's world) and saves it there on exit; the mapper journals its keyframes "
                 "there, so the occupancy map follows. An empty or new folder: this flight's map is saved there");
  app.add_option("--await-map", o.await_map_s,
                 "--map: seconds the estimator's STATE waits for the map's world before flying on its own")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_flag("--localize-only", o.localize_only,
               "--map: on an existing map, SLAM localises only (keyframes only where the vehicle leaves the map) and "
               "the mapper updates the occupancy map from the frames SLAM locates in it")
      ->needs(map_option);
  CLI::Option* localize_option = app.get_option("--localize-only");
  app.add_flag("--no-map-update", o.no_map_update,
               "--localize-only: the mapper does not insert the frames SLAM locates (keyframes made where the vehicle "
               "leaves the map still go in)")
      ->needs(localize_option);
  app.add_flag("--list", o.list, "Print the processes the command would start, and exit");
  return app.run(argc, argv, [&] { return launch(o); });
}
