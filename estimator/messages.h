#pragma once
// Conversions between the estimator's library types and its LCM messages (imu_t,
// vo_update_t, slam_correction_t -> library inputs; EstimatorOutput -> state_t). This is the
// only file of the component that knows the messages; it is a separate library
// (kestrel_estimator_messages) so that the filter itself stays free of LCM.
//
// Every *_from_message throws InputError naming the channel for a message the estimator
// cannot use (an IMU reading with nothing in it, a non-finite value, a corrupt pose). A VO
// failure (status != OK) converts to a VoUpdate with ok = false and its pose ignored.

#include <cstdint>
#include <string>

#include "estimator/estimator.h"
#include "kestrel/imu_t.hpp"
#include "kestrel/slam_correction_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vo_update_t.hpp"

namespace kestrel::estimator {

/// The reading of `m`, with the parts its fields say it has; throws InputError naming
/// `channel` for a reading with neither part, a non-finite value or a negative utime.
ImuReading imu_from_message(const kestrel::imu_t& m, const std::string& channel);
VoUpdate vo_from_message(const kestrel::vo_update_t& m, const std::string& channel);
PoseCorrection correction_from_message(const kestrel::slam_correction_t& m,
                                       const std::string& channel);

/// STATE for an output of the estimator `mode` selected (filter says which IMU filter); `seq`
/// numbers the published states.
kestrel::state_t state_to_message(const EstimatorOutput& out, EstimatorMode mode,
                                  FilterKind filter, int64_t seq);

}  // namespace kestrel::estimator
