#pragma once
// Runs the odometry over a recorded RGB-D sequence in one process and scores it: the engine of
// `kestrel vo --tum`, `kestrel vo-ablation` and the data tests. Not part of kestrel_vo (it
// reads files and a clock); it times process() alone, the figure the baselines report, as the
// CPU time of the calling thread (one core, insensitive to other jobs on a shared machine).
//
// Invariants: frames are fed in sequence order; the trajectory holds T_world_camera (world =
// first frame's camera) at exactly the frames whose status is ok, plus the first frame.
// Accuracy figures exist only when measured (RunFigures::scored): a run that estimated nothing
// has none, never zeros that read as a perfect score, and require_usable() refuses it.

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "common/rgbd_frame.h"
#include "common/trajectory.h"
#include "vo/odometry.h"
#include "vo/sensor_profile.h"

namespace kestrel::vo {

struct SequenceRun {
  std::vector<VoResult> results;     ///< one per frame
  std::vector<double> process_ms;    ///< thread CPU time of VisualOdometry::process(), per frame
  std::vector<int64_t> frame_utimes; ///< every frame fed, in order
  Trajectory trajectory;             ///< T_world_camera where the odometry gave one
};

/// One counter per VoStatus value (vo/status.h: kOk = 0 .. kBadInput = 7).
constexpr size_t kVoStatusCount = 8;

struct RunFigures {
  size_t frames = 0;
  size_t ok = 0;                    ///< frames with status ok
  std::array<size_t, kVoStatusCount> by_status{};  ///< frames per status, indexed by its value
  /// The accuracy figures below (ATE .. gross) were measured: ground truth exists, some frame
  /// has a motion and at least two frames with a pose have ground truth. Otherwise they are 0
  /// and `not_scored` says why.
  bool scored = false;
  std::string not_scored;
  size_t scored_frames = 0;         ///< frames with both an estimate and ground truth
  double ate_rmse_m = 0.0;
  double rpe_translation_mps = 0.0; ///< RMSE over 1 s pairs
  double rpe_rotation_degps = 0.0;
  double velocity_error_mps = 0.0;  ///< mean frame-to-frame velocity error
  double gross_percent = 0.0;
  size_t gross = 0;
  double median_ms = 0.0;
  double p95_ms = 0.0;
  double mean_nees = 0.0;           ///< over frames with ground truth at both ends (6 if consistent)
  double nees_within_95 = 0.0;      ///< fraction of frames with NEES under the 95 % chi2(6) bound
  size_t nees_frames = 0;
};

/// Decoded frames of a TUM sequence folder (all of them; about 1.5 MB each at VGA).
struct LoadedSequence {
  std::string folder;
  std::vector<RgbdFrame> frames;  ///< the RGB images with a depth image (never empty)
  Trajectory ground_truth;        ///< empty if the folder has none
  size_t rgb_images = 0;          ///< listed in rgb.txt; those without depth are not in frames
  int64_t max_time_difference_us = 0;  ///< the RGB-depth association tolerance used
};
/// Throws InputError for a folder that cannot be read or whose lists pair no frame
/// (tum::TumSequence).
LoadedSequence load_tum_sequence(const std::string& folder);

/// The sensor profile of the recording in `folder`: the one its camera.txt names (the
/// simulator's TUM-format exports name `simulator`), else kinect1's for a freiburg1 recording
/// (named as TUM names them, tum::detect_camera), else "default" (the built-in defaults: e.g.
/// freiburg2/3, whose timing was not measured). InputError naming camera.txt and its line for a
/// bad camera.txt (tum::read_camera_file).
const sensors::SensorProfile& tum_sensor(const std::string& folder);

/// `options` with the profile of the recording in `folder` (tum_sensor()). Every offline run
/// (kestrel-vo --tum, the ablation, the data tests, the benchmark) applies it before any --set.
VoOptions with_tum_sensor(const std::string& folder, VoOptions options);

/// Feeds every frame to a fresh VisualOdometry(options).
SequenceRun run_sequence(const std::vector<RgbdFrame>& frames, const VoOptions& options);

/// The figures of ../shared/BASELINES.md (tools/eval with its defaults) plus timing and NEES.
RunFigures score(const SequenceRun& run, const Trajectory& ground_truth);

/// "ok 187, no reference 1, too little valid depth 2": the frames by status, in the order of
/// the statuses, the ones no frame had left out.
std::string status_summary(const RunFigures& figures);

/// Throws InputError naming `folder` when the odometry's `results` (one per frame, in order:
/// SequenceRun::results, or the VO within another offline run such as kestrel-slam --tum) hold
/// nothing usable: no frame with a motion (no valid depth anywhere, no features, a single
/// frame...). The message counts the frames by status and quotes the first failure, so the
/// user learns what to fix.
void require_usable(const std::vector<VoResult>& results, const std::string& folder);

/// Per-frame status and counts, the figures and the options as JSON text.
std::string stats_json(const SequenceRun& run, const RunFigures& figures, const std::string& variant);

}  // namespace kestrel::vo
