#pragma once
// The odometry's options for a camera: VoOptions{} are the simulator's camera but for its
// keyframe cap (global shutter, depth and colour captured together, covariance floors fitted
// on its rendered frames); a camera's profile (sensors/sensor_profile.h, one YAML file per camera model in
// sensors/profiles/) says how it differs: its rolling shutter, when its depth was captured,
// and the errors it makes that its pixel and depth noise do not say.

#include "sensors/sensor_profile.h"
#include "vo/options.h"

namespace kestrel::vo {

/// `options` with what `profile` sets: the rolling shutter's readout; the depth's capture time
/// (compensated, from the stamps or not, with the profile's extra latency); the covariance
/// floors and per-radian growth; the dense term's weight; the near-keyframe rule; the keyframe
/// floors' cap. A field the
/// profile leaves out keeps `options`' value. std::invalid_argument if the result is not valid.
VoOptions with_sensor(const sensors::SensorProfile& profile, VoOptions options);

}  // namespace kestrel::vo
