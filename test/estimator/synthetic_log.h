#pragma once
// LCM logs synthesised for the estimator's message-side tests: a still vehicle (yaw 0.3)
// with a biased, noisy IMU at 200 Hz, the synthetic VO at 30 Hz arriving 30 ms after its
// frame, and one SLAM correction (the true pose) 1 s late, written in arrival order as the
// processes would have logged them; optionally with a duplicate IMU sample, a NaN sample and
// a corrupt VO message at sample 300.

#include <string>
#include <vector>

#include "estimator/estimator.h"
#include "kestrel/imu_t.hpp"
#include "kestrel/vo_update_t.hpp"

namespace kestrel::estimator::test {

kestrel::imu_t imu_message(const ImuSample& s);
kestrel::vo_update_t vo_message(const VoUpdate& u);

struct SyntheticLog {
  std::vector<ImuSample> imu;  ///< as generated, in order
  std::vector<VoUpdate> vo;    ///< in delivery order (each 30 ms after its frame)
};
/// Writes the log to `path` (with GROUND_TRUTH of the body at every IMU sample when
/// `with_ground_truth`) and returns what went into it.
SyntheticLog write_log(const std::string& path, double duration_s, bool with_bad_messages,
                       bool with_ground_truth = false);

}  // namespace kestrel::estimator::test
