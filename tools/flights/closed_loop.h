#pragma once
// One closed-loop flight of a planned path with the whole system in the loop: the simulator's
// vehicle (wind, rendered RGB-D and IMU from the true pose) and kestrel-vo, -estimator,
// -follow (flying the waypoints on STATE, never the truth), -slam and -mapper, as separate
// processes over LCM, driven in lock-step by the simulator (`sim --lockstep`), so the flight
// is the same on any machine and under any load.
//
// The caller has made the network private (tools/launch/isolation.h) and gives the folder of
// the kestrel tools. Everything of the flight stays in its folder: waypoints.txt, each
// process's log (<name>.log) and the recording flight.lcmlog (GROUND_TRUTH and what the
// processes published, but the map). A watcher (`kestrel soak`) can look at the processes
// while they fly.

#include <Eigen/Core>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "tools/launch/supervisor.h"

namespace kestrel::flights {

struct FlightSetup {
  std::string world;  ///< the simulator's --world
  std::string map;    ///< its --map ("" for none)
  Eigen::Vector4d start = Eigen::Vector4d::Zero();  ///< x, y, z, yaw: the vehicle's and the estimator's start
  std::vector<Eigen::Vector4d> waypoints;           ///< the plan, start first
  uint64_t seed = 1;           ///< the simulator's (sensor noise and wind)
  double duration_s = 60.0;    ///< of simulated flight
  double speed_m_s = 0.5;      ///< the follower's cruise speed
  double ack_timeout_s = 60.0;  ///< lock-step: longest wait for a process
  /// kestrel-vo's --set KEY=VALUE settings (kestrel-vo --print-config keys), checked by the caller.
  std::vector<std::string> vo_settings;
  std::filesystem::path dir;    ///< made if absent
  /// Write flight.lcmlog; a long flight goes without (STATE alone is ~0.4 MB per second).
  bool record = true;
};

struct FlightRun {
  bool ok = false;      ///< every process ran to the end, the simulator exited 0
  std::string failure;  ///< else why, naming the process and its last log lines
  int contacts = -1;    ///< the simulator's count of touches of the world
  std::filesystem::path recording;  ///< flight.lcmlog; empty when not recorded
};

/// Called on the flight's thread about every 50 ms while the processes run (their names and
/// pids: Supervisor::children(), pid -1 once one has ended), and once more with `ending` true
/// when the simulator has ended, before the others are stopped.
using FlightWatch = std::function<void(const launch::Supervisor& processes, bool ending)>;

/// Runs the flight; returns once the simulated `duration_s` is flown (or `interrupted()`).
/// Throws InputError when a tool is missing or the folder cannot be written.
FlightRun fly(const FlightSetup& setup, const std::filesystem::path& tool_dir, const std::string& lcm_url,
              const std::function<bool()>& interrupted, const FlightWatch& watch = {});

/// Puts this process (call it before any thread starts) in a private network that the flights'
/// processes share and nothing leaves; UnavailableError naming `tool` when none can be made.
void enter_flight_network(const std::string& tool);

/// Makes `folder` (and its parents) for a tool's outputs; InputError naming it when it cannot.
std::filesystem::path make_output_folder(const std::string& folder);

/// The flight time a plan needs: its length at `speed_m_s`, a margin for the turns, the
/// controller's lag and the start, and a hold at the goal.
double flight_duration_s(const std::vector<Eigen::Vector4d>& waypoints, double speed_m_s);

}  // namespace kestrel::flights
