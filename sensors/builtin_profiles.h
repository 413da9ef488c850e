#pragma once
// The camera profiles kestrel ships: sensors/profiles/*.yaml, embedded in the build so that
// every tool has them wherever it runs (one source, the files; nothing typed twice).
//
// Invariants: every built-in file parses (a test checks it, and the first use throws
// std::logic_error otherwise); names are unique; "default" (what a camera without a profile
// gets: it sets nothing) and "simulator" are among them.

#include <optional>
#include <string>
#include <vector>

#include "sensors/sensor_profile.h"

namespace kestrel::sensors {

/// Every built-in profile, in name order.
const std::vector<SensorProfile>& builtin_profiles();
/// Their names, for help texts and errors.
std::vector<std::string> builtin_profile_names();
/// The same as one list, "default, kinect1, simulator".
std::string builtin_profile_list();
/// The built-in profile called `name`, or nothing.
std::optional<SensorProfile> find_builtin_profile(const std::string& name);
/// The built-in profile called `name`; std::invalid_argument naming the built-in ones if none is.
const SensorProfile& builtin_profile(const std::string& name);

/// The profile for frames whose sensor model is `sensor_model` (RgbdFrame::sensor): the
/// built-in one of that name, "default" (the built-in defaults) for any other name, "" (unknown)
/// included.
const SensorProfile& profile_of_sensor(const std::string& sensor_model);

}  // namespace kestrel::sensors
