#include "vo/sensor_profile.h"

#include "common/rgbd_frame.h"

namespace kestrel::vo {

VoOptions with_sensor(SensorProfile profile, VoOptions options) {
  if (profile == SensorProfile::kSimulator) return options;
  options.depth.rolling_shutter_readout_s = kKinect1RollingShutterReadoutS;
  options.depth.compensate_time_offset = true;
  options.depth.time_offset_from_stamps = true;
  options.depth.time_offset_s = -kKinect1DepthExtraLatencyS;
  options.covariance.translation_floor_m = kKinect1TranslationFloorM;
  options.covariance.rotation_floor_rad = kKinect1RotationFloorRad;
  options.covariance.translation_per_rad_m = kKinect1TranslationPerRadM;
  options.covariance.rotation_per_rad = kKinect1RotationPerRad;
  options.dense.weight = kKinect1DenseWeight;
  options.keyframe.min_inliers_to_keep_near = kKinect1MinInliersToKeepNear;
  options.validate();
  return options;
}

std::string to_string(SensorProfile profile) {
  return profile == SensorProfile::kKinect1 ? sensor_model::kKinect1 : sensor_model::kSimulator;
}

SensorProfile profile_of_sensor(const std::string& sensor_model) {
  return parse_sensor_profile(sensor_model).value_or(SensorProfile::kSimulator);
}

std::optional<SensorProfile> parse_sensor_profile(const std::string& name) {
  for (const SensorProfile p : {SensorProfile::kSimulator, SensorProfile::kKinect1})
    if (to_string(p) == name) return p;
  return std::nullopt;
}

}  // namespace kestrel::vo
