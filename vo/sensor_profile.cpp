#include "vo/sensor_profile.h"

namespace kestrel::vo {

VoOptions with_sensor(const sensors::SensorProfile& profile, VoOptions options) {
  const auto& t = profile.timing;
  if (t.rolling_shutter_readout_s) options.depth.rolling_shutter_readout_s = *t.rolling_shutter_readout_s;
  if (t.depth_time_from_stamps || t.depth_extra_latency_s) {
    options.depth.compensate_time_offset = true;
    if (t.depth_time_from_stamps) options.depth.time_offset_from_stamps = *t.depth_time_from_stamps;
    if (t.depth_extra_latency_s) options.depth.time_offset_s = -*t.depth_extra_latency_s;
  }
  const auto& v = profile.vo;
  if (v.translation_floor_m) options.covariance.translation_floor_m = *v.translation_floor_m;
  if (v.rotation_floor_rad) options.covariance.rotation_floor_rad = *v.rotation_floor_rad;
  if (v.translation_per_rad_m) options.covariance.translation_per_rad_m = *v.translation_per_rad_m;
  if (v.rotation_per_rad) options.covariance.rotation_per_rad = *v.rotation_per_rad;
  if (v.dense_weight) options.dense.weight = *v.dense_weight;
  if (v.min_inliers_to_keep_near) options.keyframe.min_inliers_to_keep_near = *v.min_inliers_to_keep_near;
  if (v.floor_cap_fraction) options.keyframe.floor_cap_fraction = *v.floor_cap_fraction;
  options.validate();
  return options;
}

}  // namespace kestrel::vo
