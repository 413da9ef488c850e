#pragma once
// kestrel-sim's messages: IMU samples and exact ground truth as LCM types. Kept apart from the
// library (which knows nothing of LCM) and from main.cpp (which only wires things up).

#include "drivers/sim/simulation.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/imu_t.hpp"

namespace kestrel::sim {

/// The IMU sample as imu_t (gyro and accelerometer, body frame).
kestrel::imu_t imu_message(int64_t utime, const ImuSample& sample);

/// The body's exact state (FRAME_BODY) with velocity, angular rate and, when `biases` is
/// given, the IMU's true biases at that time.
kestrel::ground_truth_t ground_truth_message(int64_t utime, const MotionState& truth, const ImuSample* biases);

}  // namespace kestrel::sim
