#pragma once
// What kestrel assumes about a camera that its frames do not say: its timing (a rolling
// shutter, when the depth was captured against the colour image) and the errors the
// odometry's and SLAM's noise models leave out on it. A profile is data: one YAML file per
// camera model in sensors/profiles/ (built in, sensors/builtin_profiles.h) or one of the user's
// (`kestrel vo --sensor my_camera.yaml`), so a new camera is a new file, not code.
//
// Every frame names its camera's model (RgbdFrame::sensor, set by the source and kept in logs);
// the profile of that name applies, "default" (which sets nothing) for a model without one. A
// field the file leaves out leaves the consumer's default as it is.
//
// Invariants of a parsed profile: the name is lower-case letters, digits, '_' or '-'; every
// number is finite and in its field's range (parse_sensor_profile says which).

#include <optional>
#include <string>

namespace kestrel::sensors {

struct SensorProfile {
  std::string name;         ///< the sensor model frames carry ("simulator", "kinect1")
  std::string description;  ///< one line, for people

  struct Timing {
    /// First-to-last row time of a rolling colour shutter, s (absent: global shutter).
    std::optional<double> rolling_shutter_readout_s;
    /// The depth's capture time is the colour stamp plus the stamps' difference (true) or the
    /// colour stamp alone (false), minus depth_extra_latency_s.
    std::optional<bool> depth_time_from_stamps;
    /// How much later after its capture the depth image is stamped than the colour image, s.
    std::optional<double> depth_extra_latency_s;
  } timing;

  struct Odometry {  ///< what the VO's noise model leaves out, and its tuning on this camera
    std::optional<double> translation_floor_m;
    std::optional<double> rotation_floor_rad;
    std::optional<double> translation_per_rad_m;
    std::optional<double> rotation_per_rad;
    std::optional<double> dense_weight;
    std::optional<int> min_inliers_to_keep_near;
    std::optional<double> floor_cap_fraction;  ///< keyframe floors' cap, share of the first match
  } vo;

  struct Slam {
    /// A loop closure's rotation sigma is at least this, rad (file: loop_rotation_floor_deg).
    std::optional<double> loop_rotation_floor_rad;
  } slam;
};

/// The profile in `yaml_text`; `source` names it in errors (a file's path, "built-in kinect1").
/// Throws std::invalid_argument naming the source and the field for malformed YAML, more than
/// one document, an unknown or repeated key, a value of the wrong type, a non-finite number or
/// one out of its range (the ranges the consumers' options accept).
SensorProfile parse_sensor_profile(const std::string& yaml_text, const std::string& source);

}  // namespace kestrel::sensors
