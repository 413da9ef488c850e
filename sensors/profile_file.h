#pragma once
// A sensor profile as a user names it on a command line: a built-in profile's name
// ("kinect1") or the path of a profile file of their own ("my_camera.yaml").

#include <string>

#include "sensors/sensor_profile.h"

namespace kestrel::sensors {

/// The built-in profile called `name_or_path`, else the profile in that file. Throws
/// std::invalid_argument when it is neither a built-in name nor an existing file (naming the
/// built-in ones), InputError when the file cannot be read or is not a valid profile.
SensorProfile load_sensor_profile(const std::string& name_or_path);

/// For a command line's --sensor: "" when `name_or_path` is a built-in name or an existing
/// file (whose content load_sensor_profile checks when it is loaded: bad input, exit 3), else
/// why not, naming the built-in profiles.
std::string check_sensor_profile_name(const std::string& name_or_path);

}  // namespace kestrel::sensors
