#include "sensors/sensor_profile.h"

#include <fmt/format.h>
#include <yaml-cpp/yaml.h>

#include <cmath>
#include <set>
#include <stdexcept>
#include <vector>

#include "common/numbers.h"

namespace kestrel::sensors {
namespace {

[[noreturn]] void fail(const std::string& source, const std::string& what) {
  throw std::invalid_argument(source + ": " + what);
}

// Every key of `node` must be one of `known`: a misspelt field is an error, never ignored.
void check_keys(const YAML::Node& node, const std::set<std::string>& known, const std::string& source,
                const std::string& where) {
  if (!node.IsMap()) fail(source, (where.empty() ? "the profile" : "'" + where.substr(0, where.size() - 1) + "'") + " must be a map of fields");
  std::set<std::string> seen;
  for (const auto& kv : node) {
    const std::string key = kv.first.as<std::string>();
    if (!seen.insert(key).second) fail(source, "field '" + where + key + "' is given twice");
    if (!known.count(key)) {
      std::string list;
      for (const auto& k : known) list += (list.empty() ? "" : ", ") + k;
      fail(source, "unknown field '" + where + key + "' (known here: " + list + ")");
    }
  }
}

// Which ends of a field's range are open: the VO's options take some only strictly inside.
enum class Range { kClosed, kOpenAbove, kOpen };

std::optional<double> number(const YAML::Node& parent, const std::string& key, double lo, double hi,
                             const std::string& source, const std::string& where, Range range = Range::kClosed) {
  const YAML::Node n = parent[key];
  if (!n) return std::nullopt;
  double v = 0.0;
  try {
    v = n.as<double>();
  } catch (const YAML::Exception&) {
    fail(source, "'" + where + key + "' is not a number");
  }
  const bool below = range == Range::kOpen ? v <= lo : v < lo;
  const bool above = range == Range::kClosed ? v > hi : v >= hi;
  if (!std::isfinite(v) || below || above)
    fail(source, fmt::format("'{}{}' is {}: must be in {}{:g}, {:g}{}", where, key, n.as<std::string>(),
                             range == Range::kOpen ? "(" : "[", lo, hi, range == Range::kClosed ? "]" : ")"));
  return v;
}

}  // namespace

SensorProfile parse_sensor_profile(const std::string& yaml_text, const std::string& source) try {
  const std::vector<YAML::Node> documents = YAML::LoadAll(yaml_text);
  if (documents.size() > 1) fail(source, "holds " + std::to_string(documents.size()) + " YAML documents: a profile is one");
  const YAML::Node root = documents.empty() ? YAML::Node() : documents.front();
  check_keys(root, {"name", "description", "timing", "vo", "slam"}, source, "");
  SensorProfile p;
  if (!root["name"]) fail(source, "no 'name' (the sensor model its frames carry)");
  if (!root["name"].IsScalar()) fail(source, "'name' is not a word");
  p.name = root["name"].as<std::string>();
  if (p.name.empty()) fail(source, "'name' is empty");
  for (const char c : p.name)
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_' || c == '-'))
      fail(source, "'name' is '" + p.name + "': only lower-case letters, digits, '_' and '-'");
  if (root["description"]) {
    if (!root["description"].IsScalar()) fail(source, "'description' is not a line of text");
    p.description = root["description"].as<std::string>();
  }

  if (const YAML::Node t = root["timing"]) {
    check_keys(t, {"rolling_shutter_readout_s", "depth_time_from_stamps", "depth_extra_latency_s"}, source, "timing.");
    p.timing.rolling_shutter_readout_s = number(t, "rolling_shutter_readout_s", 0.0, 0.1, source, "timing.", Range::kOpenAbove);
    if (t["depth_time_from_stamps"]) {
      try {
        p.timing.depth_time_from_stamps = t["depth_time_from_stamps"].as<bool>();
      } catch (const YAML::Exception&) {
        fail(source, "'timing.depth_time_from_stamps' is not true or false");
      }
    }
    p.timing.depth_extra_latency_s = number(t, "depth_extra_latency_s", -0.1, 0.1, source, "timing.", Range::kOpen);
  }
  if (const YAML::Node v = root["vo"]) {
    check_keys(v, {"translation_floor_m", "rotation_floor_rad", "translation_per_rad_m", "rotation_per_rad",
                   "dense_weight", "min_inliers_to_keep_near", "floor_cap_fraction"},
               source, "vo.");
    p.vo.translation_floor_m = number(v, "translation_floor_m", 0.0, 1.0, source, "vo.");
    p.vo.rotation_floor_rad = number(v, "rotation_floor_rad", 0.0, 1.0, source, "vo.");
    p.vo.translation_per_rad_m = number(v, "translation_per_rad_m", 0.0, 10.0, source, "vo.");
    p.vo.rotation_per_rad = number(v, "rotation_per_rad", 0.0, 10.0, source, "vo.");
    p.vo.dense_weight = number(v, "dense_weight", 0.0, 100.0, source, "vo.");
    if (const auto n = number(v, "min_inliers_to_keep_near", 0.0, 100000.0, source, "vo.")) {
      if (*n != std::floor(*n)) fail(source, "'vo.min_inliers_to_keep_near' must be a whole number");
      p.vo.min_inliers_to_keep_near = static_cast<int>(*n);
    }
    p.vo.floor_cap_fraction = number(v, "floor_cap_fraction", 0.0, 1.0, source, "vo.");
  }
  if (const YAML::Node s = root["slam"]) {
    check_keys(s, {"loop_rotation_floor_deg"}, source, "slam.");
    if (const auto deg = number(s, "loop_rotation_floor_deg", 0.0, 45.0, source, "slam."))
      p.slam.loop_rotation_floor_rad = *deg * kPi / 180.0;
  }
  return p;
} catch (const YAML::Exception& e) {  // malformed YAML, or a field of the wrong kind
  fail(source, std::string("not a sensor profile: ") + e.what());
}

}  // namespace kestrel::sensors
