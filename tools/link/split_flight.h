#pragma once
// One closed-loop flight of the whole system split over the emulated link: `kestrel launch
// all --link` with the sim vehicle in the room as the onboard source, and what came of it.
// Used by the split test (test/link/split_flight_test.cpp) and by `kestrel link-sweep`.
//
// The flight, live at the sensors' own pace (nothing onboard waits for the link; the
// simulator is not in lock-step): the vehicle takes off holding its start (8, 3.5, 1.3) on
// the estimator's STATE; after `hover_s` a ground-station user (kestrel goto, offboard) asks
// for a plan to 1.5 m ahead (asking once more if it was not flown in 20 s: a PLAN lost on
// the link is not sent again by anyone) and, once there, for one back to 1 m ahead of the start (the
// start lies behind the first camera, and half a metre ahead is inside its shortest range:
// the planner never learns they are free); then it holds there until the end. The source
// sends raw frames, as a Kinect does, and rgbd-codec compresses those that cross. Onboard,
// an lcm-logger records GROUND_TRUTH, STATE, PLAN, SLAM_CORRECTION and VO_UPDATE as they
// arrive there.
//
// What is measured: the true deviation while holding (from 3 s after the first truth until
// the first request, and from 2 s after the return until the end): the distance of the
// simulator's true body position from (8, 3.5, 1.3), then from (9, 3.5, 1.3) (or, if a
// request was not flown, from where the vehicle was told to hold instead). Corrections are
// those that reached the onboard side (the log) and those the estimator applied (its log);
// plans those that reached it with status OK; the mapper's keyframes those it inserted; the
// link's drops are its lost and queue-full datagrams, both ways.
//
// The recorder (lcm-logger, onboard) and the user (a shell script running goto, offboard)
// are processes of the launch's set, so the flight needs only what `launch --link` needs
// (root or user namespaces) and lcm-logger. Everything it writes goes under `out_dir`
// (whose path must hold no blank; the launch's logs in out_dir/logs).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace kestrel::link {

struct SplitFlightOptions {
  std::filesystem::path bin_dir;  ///< where kestrel-launch and the other tools are
  std::filesystem::path out_dir;  ///< made if absent
  double loss_percent = 10;
  double delay_ms = 30, jitter_ms = 10, rate_mbit = 20;
  uint64_t seed = 1;
  double duration_s = 55;  ///< of the simulator's flight
  double hover_s = 8;      ///< wall seconds from the start until the first request
};

/// A frame VO read but could not measure a motion on (not one without a reference: the first,
/// or the first after a reset), as VO_UPDATE said it.
struct VoFailure {
  int64_t utime = 0;
  int status = 0;  ///< vo_update_t::STATUS_*
  int features = 0, matches = 0, inliers = 0;
};

struct SplitFlightResult {
  int launch_exit = -1;
  int goto_out_exit = -1, goto_back_exit = -1;  ///< kestrel goto's exits (0: arrived)
  int goto_out_attempts = 0, goto_back_attempts = 0;  ///< requests made (a second if the first was not flown)
  int hover_samples = 0;
  double deviation_mean_m = 0, deviation_max_m = 0;
  int corrections_received = 0;   ///< SLAM_CORRECTION messages logged onboard
  int corrections_applied = -1;   ///< from the estimator's last lines (-1: not found)
  int plans_answered = 0;         ///< PLAN messages with status OK logged onboard
  int plans_received = 0;         ///< PLAN messages of any status logged onboard (no path, ...)
  int mapper_keyframes = -1;      ///< frames the mapper inserted (-1: not found)
  int slam_keyframes = -1;        ///< (-1: not found)
  int vo_frames = -1, vo_motions = -1;  ///< frames VO read and those it measured (-1: not found)
  std::vector<VoFailure> vo_failures;  ///< from the onboard log, in order
  int states = 0;                 ///< STATE messages logged onboard
  double state_max_gap_s = 0;     ///< the longest wall time between two of them (onboard never waits)
  int64_t datagrams_offered = 0, datagrams_lost = 0, datagrams_queue_full = 0;  ///< both ways
  double up_mbit_s = 0;           ///< mean offered rate up the link
  std::string problems;           ///< what could not be read, one per line (empty: all)
};

/// Flies once (about duration_s + 5 s of wall time) and reads the results. Never throws for
/// a flight that went wrong: the result says what happened (launch_exit, problems).
SplitFlightResult fly_split(const SplitFlightOptions& options);

}  // namespace kestrel::link
