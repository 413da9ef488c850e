#include "sensors/builtin_profiles.h"

#include <algorithm>
#include <stdexcept>
#include <string>
#include <utility>

namespace kestrel::sensors {

// The embedded files, {file name, text} (generated: sensors/CMakeLists.txt).
const std::vector<std::pair<std::string, std::string>>& builtin_profile_texts();

const std::vector<SensorProfile>& builtin_profiles() {
  static const std::vector<SensorProfile> profiles = [] {
    // A shipped file that breaks the header's invariants is a bug: std::logic_error.
    std::vector<SensorProfile> out;
    for (const auto& [file, text] : builtin_profile_texts()) {
      try {
        out.push_back(parse_sensor_profile(text, "built-in sensors/profiles/" + file));
      } catch (const std::invalid_argument& e) {
        throw std::logic_error(e.what());
      }
      if (file != out.back().name + ".yaml")
        throw std::logic_error("sensors/profiles/" + file + " names its profile '" + out.back().name + "'");
    }
    std::sort(out.begin(), out.end(), [](const SensorProfile& a, const SensorProfile& b) { return a.name < b.name; });
    for (const char* required : {"default", "simulator"})
      if (std::none_of(out.begin(), out.end(), [&](const SensorProfile& p) { return p.name == required; }))
        throw std::logic_error(std::string("sensors/profiles/ has no ") + required + ".yaml");
    return out;
  }();
  return profiles;
}

std::vector<std::string> builtin_profile_names() {
  std::vector<std::string> names;
  for (const auto& p : builtin_profiles()) names.push_back(p.name);
  return names;
}

std::string builtin_profile_list() {
  std::string list;
  for (const auto& n : builtin_profile_names()) list += (list.empty() ? "" : ", ") + n;
  return list;
}

std::optional<SensorProfile> find_builtin_profile(const std::string& name) {
  for (const auto& p : builtin_profiles())
    if (p.name == name) return p;
  return std::nullopt;
}

const SensorProfile& builtin_profile(const std::string& name) {
  for (const auto& p : builtin_profiles())
    if (p.name == name) return p;
  throw std::invalid_argument("no built-in sensor profile '" + name + "' (built in: " + builtin_profile_list() + ")");
}

const SensorProfile& profile_of_sensor(const std::string& sensor_model) {
  for (const auto& p : builtin_profiles())
    if (p.name == sensor_model) return p;
  return builtin_profile("default");
}

}  // namespace kestrel::sensors
