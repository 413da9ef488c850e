#include "sensors/profile_file.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

#include "common/error.h"
#include "sensors/builtin_profiles.h"

namespace kestrel::sensors {

std::string check_sensor_profile_name(const std::string& name_or_path) {
  if (find_builtin_profile(name_or_path)) return "";
  std::error_code ec;
  if (std::filesystem::is_regular_file(name_or_path, ec)) return "";
  return "'" + name_or_path + "' is neither a built-in sensor profile (" + builtin_profile_list() +
         ") nor a profile file";
}

SensorProfile load_sensor_profile(const std::string& name_or_path) {
  if (auto p = find_builtin_profile(name_or_path)) return *p;
  if (const std::string why = check_sensor_profile_name(name_or_path); !why.empty())
    throw std::invalid_argument(why);
  std::ifstream in(name_or_path, std::ios::binary);
  std::ostringstream text;
  text << in.rdbuf();
  if (!in || in.bad()) throw InputError(name_or_path + ": cannot be read");
  try {
    return parse_sensor_profile(text.str(), name_or_path);
  } catch (const std::invalid_argument& e) {
    throw InputError(e.what());
  }
}

}  // namespace kestrel::sensors
