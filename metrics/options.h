#pragma once
// Options of the trajectory evaluation (kestrel-eval). Every field has its default and unit;
// the defaults follow the protocol of ../shared/BASELINES.md so that figures are comparable.

#include <cstdint>

namespace kestrel::metrics {

struct EvalOptions {
  /// Ground truth is interpolated at a frame's time only when the samples on both sides lie
  /// within this many microseconds of it (Trajectory::at); otherwise the frame is unscored.
  int64_t gt_max_gap_us = 20000;
  /// The estimate is looked up at a frame's time the same way; 0 = exact time stamps only (a
  /// VO or TUM trajectory has a pose per frame). Raise it for a STATE trajectory at IMU rate.
  int64_t est_max_gap_us = 0;
  /// Rigidly align the estimated positions to the ground truth before the ATE (no scale).
  bool align = true;
  /// RPE time step, seconds.
  double rpe_delta_s = 1.0;
  /// An RPE pair is used only if its span differs from rpe_delta_s by at most this, seconds.
  double rpe_tolerance_s = 0.1;
  /// A frame whose frame-to-frame velocity error exceeds this (m/s) is a gross failure.
  double gross_velocity_mps = 1.0;
  /// The first scored frame after a ground-truth gap counts as a gross failure, its motion
  /// being unverifiable: the convention of ../shared/BASELINES.md (see tools/eval/README.md).
  bool gross_after_gt_gap = true;
};

}  // namespace kestrel::metrics
