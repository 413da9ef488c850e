#include "tools/flights/closed_loop.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <optional>
#include <regex>
#include <thread>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/numbers.h"
#include "tools/launch/isolation.h"
#include "tools/launch/process_set.h"
#include "tools/launch/supervisor.h"

namespace kestrel::flights {
namespace fs = std::filesystem;

namespace {

std::string csv(double a, double b, double c) { return fmt::format("{:.6f},{:.6f},{:.6f}", a, b, c); }

// The simulator's summary line "contacts: N" (-1 if absent).
int read_contacts(const fs::path& sim_log) {
  std::ifstream in(sim_log);
  const std::regex line("^contacts: ([0-9]+)$");
  int contacts = -1;
  std::smatch m;
  for (std::string l; std::getline(in, l);)
    if (std::regex_match(l, m, line)) contacts = std::stoi(m[1]);
  return contacts;
}

}  // namespace

double flight_duration_s(const std::vector<Eigen::Vector4d>& waypoints, double speed_m_s) {
  double length = 0.0, turn = 0.0;
  for (size_t i = 1; i < waypoints.size(); ++i) {
    length += (waypoints[i].head<3>() - waypoints[i - 1].head<3>()).norm();
    turn += std::abs(wrap_angle(waypoints[i][3] - waypoints[i - 1][3]));
  }
  // The estimator's still start (0.5 s) and the first keyframes, the path at cruise speed with
  // 40 % for corners and the stop, turning at 1 rad/s, then 5 s of hold at the goal.
  return 3.0 + 1.4 * length / speed_m_s + turn + 5.0;
}

FlightRun fly(const FlightSetup& s, const fs::path& tool_dir, const std::string& lcm_url,
              const std::function<bool()>& interrupted, const FlightWatch& watch) {
  std::error_code ec;
  fs::create_directories(s.dir, ec);
  if (ec) throw InputError(s.dir.string() + ": cannot make the folder: " + ec.message());
  const fs::path waypoints = s.dir / "waypoints.txt";
  std::string text = "# x y z yaw: the plan flown (kestrel fly-plans)\n";
  for (const Eigen::Vector4d& w : s.waypoints) text += fmt::format("{:.6f} {:.6f} {:.6f} {:.6f}\n", w[0], w[1], w[2], w[3]);
  write_file_atomically(waypoints.string(), text);

  FlightRun run;
  run.recording = s.dir / "flight.lcmlog";
  fs::remove(run.recording, ec);  // a recording of an earlier run must not pass for this one's
  const std::string start = csv(s.start[0], s.start[1], s.start[2]);
  std::vector<std::string> vo = {"vo"};
  for (const std::string& kv : s.vo_settings) vo.insert(vo.end(), {"--set", kv});
  launch::ProcessSet set = {
      {"vo", vo, "onboard"},
      {"estimator", {"estimator", "--init-position", start, "--init-yaw", fmt::format("{:.6f}", s.start[3])}, "onboard"},
      {"follow", {"follow", "--waypoints", waypoints.string(), "--speed", fmt::format("{}", s.speed_m_s)}, "onboard"},
      {"slam", {"slam"}, "offboard"},
      {"mapper", {"mapper"}, "offboard"},
  };
  std::vector<std::string> sim = {"sim", "--world", s.world, "--flight", "vehicle", "--start",
                                  csv(s.start[0], s.start[1], s.start[2]) + fmt::format(",{:.6f}", s.start[3]),
                                  "--seed", std::to_string(s.seed), "--duration", fmt::format("{:.3f}", s.duration_s),
                                  "--lockstep", fmt::format("{}", s.ack_timeout_s), "--expect",
                                  "vo,estimator,follow,slam,mapper"};
  if (s.record) {
    // the map is large and not scored: its MAP_OCTOMAP stays out
    sim.insert(sim.end(), {"--record", run.recording.string(), "--record-channels",
                           "STATE|VO_UPDATE|SLAM_GRAPH|SLAM_CORRECTION|VEHICLE_COMMAND"});
  } else {
    run.recording.clear();
  }
  if (!s.map.empty()) sim.insert(sim.end(), {"--map", s.map});
  set.push_back({"sim", sim, "source"});
  std::vector<fs::path> executables;
  for (const auto& p : set) executables.push_back(launch::resolve_executable(p.argv[0], tool_dir));

  launch::SupervisorOptions options;
  options.log_dir = s.dir;
  options.environment = {"LCM_DEFAULT_URL=" + lcm_url};
  launch::Supervisor supervisor(set, executables, options);
  std::optional<launch::Ending> sim_ending;
  std::string failure;
  const auto note = [&](const std::vector<launch::ChildEvent>& events, bool stopping) {
    for (const auto& e : events) {
      if (e.kind != launch::ChildEvent::kEnded || stopping) continue;
      if (e.name == "sim") {
        sim_ending = e.ending;
      } else if (failure.empty()) {
        failure = fmt::format("{} {} during the flight:\n{}", e.name, e.ending.description,
                              launch::log_tail(s.dir / (e.name + ".log"), 5));
      }
    }
  };
  note(supervisor.start_all(), false);
  while (!sim_ending && !interrupted()) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    note(supervisor.poll(), false);
    if (watch && !sim_ending) watch(supervisor, false);
  }
  if (watch && sim_ending) watch(supervisor, true);
  note(supervisor.stop_all(), true);
  run.contacts = read_contacts(s.dir / "sim.log");
  if (interrupted()) {
    run.failure = "interrupted";
  } else if (sim_ending->code != 0) {
    run.failure = fmt::format("the simulator {}:\n{}", sim_ending->description, launch::log_tail(s.dir / "sim.log", 8));
  } else {
    run.failure = failure;
  }
  run.ok = run.failure.empty();
  return run;
}

void enter_flight_network(const std::string& tool) {
  try {
    spdlog::info("private network: {}", launch::to_string(launch::enter_private_network()));
  } catch (const launch::IsolationError& e) {
    throw UnavailableError(std::string(e.what()) + " (kestrel " + tool + " runs its processes in a private network)");
  }
}

fs::path make_output_folder(const std::string& folder) {
  const fs::path out(folder);
  std::error_code ec;
  fs::create_directories(out, ec);
  if (ec) throw InputError(folder + ": cannot make the folder: " + ec.message());
  return out;
}

}  // namespace kestrel::flights
