#pragma once
// The estimator run in process over an LCM log (what `kestrel estimate` and
// `kestrel fit-vo-noise` do): the log's messages are handed to the library in the log's
// order, which is their arrival order when it was recorded, so a late SLAM correction in
// the log is late here too and the result equals what the process would have published.
//
// Part of kestrel_estimator_messages (it reads messages); the filter knows nothing of it.
// Messages the estimator cannot use (corrupt, of another type, missing a field, NaN) are
// skipped and counted with the first reason kept; a damaged log is read around the damage.

#include <cstdint>
#include <string>
#include <vector>

#include "common/trajectory.h"
#include "estimator/estimator.h"

namespace kestrel::estimator {

struct LogChannels {
  std::string imu = "IMU";
  std::string vo = "VO_UPDATE";
  std::string correction = "SLAM_CORRECTION";
  std::string ground_truth = "GROUND_TRUTH";
};

struct LogSkips {
  int64_t rejected = 0;      ///< messages that could not be used
  std::string first_reason;  ///< one line naming the channel, of the first of them
  std::string damage;        ///< the log reader's damage report ("" if none)
};

struct LogRunResult {
  /// The estimator that ran (state_estimator.h); kAuto if nothing decided it.
  EstimatorMode mode = EstimatorMode::kAuto;
  Trajectory trajectory;  ///< T_world_body of every state published (state_estimator.h)
  std::vector<Eigen::Vector3d> velocity;  ///< v_world_body at the same utimes
  int64_t imu_messages = 0, vo_messages = 0, correction_messages = 0;
  EstimatorCounters counters;
  LogSkips skips;
};

/// Runs an estimator with `options` over the log at `path`. Messages logged in the first
/// skip_s seconds are left out (an estimator started in flight). Throws InputError if the log
/// cannot be read, holds neither IMU nor VO messages, or no IMU message in mode kImu.
LogRunResult run_log(const std::string& path, const EstimatorOptions& options,
                     const LogChannels& channels = {}, double skip_s = 0.0);

struct VoAndTruth {
  std::vector<VoUpdate> updates;
  Trajectory truth;  ///< T_world_body (camera ground truth is moved to the body)
  LogSkips skips;
};

/// The VO updates and the ground truth of a log, for fitting the VO noise. A camera-frame
/// ground truth is converted with the VO's camera mounting. Throws InputError if the log
/// cannot be read or has no VO update.
VoAndTruth read_vo_and_truth(const std::string& path, const LogChannels& channels = {});

}  // namespace kestrel::estimator
