#pragma once
// kestrel-sim's messages: IMU samples and exact ground truth as LCM types. Kept apart from the
// library (which knows nothing of LCM) and from main.cpp (which only wires things up).

#include "drivers/sim/simulation.h"
#include "kestrel/ground_truth_t.hpp"
#include "drivers/sim/vehicle.h"
#include "kestrel/imu_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vehicle_command_t.hpp"

namespace kestrel::sim {

/// The IMU sample as imu_t (gyro and accelerometer, body frame).
kestrel::imu_t imu_message(int64_t utime, const ImuSample& sample);

/// The body's exact state (FRAME_BODY) with velocity, angular rate and, when `biases` is
/// given, the IMU's true biases at that time.
kestrel::ground_truth_t ground_truth_message(int64_t utime, const MotionState& truth, const ImuSample* biases);

/// A VEHICLE_COMMAND for the closed-loop vehicle. Throws InputError (naming the channel) on
/// an unknown mode or a non-finite field the mode uses.
VehicleCommand vehicle_command(const kestrel::vehicle_command_t& m);

/// What the vehicle's controller takes from the estimator's STATE: position, velocity, yaw.
/// Returns false (use nothing) while the filter is initialising or failed, or on non-finite
/// values.
bool vehicle_estimate(const kestrel::state_t& m, VehicleEstimate& out);

}  // namespace kestrel::sim
