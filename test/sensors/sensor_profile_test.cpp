// Camera profiles as data: the shipped files parse and say what their comments say; a user's
// file loads; every kind of bad file is refused naming the field, never half-read.

#include <gtest/gtest.h>

#include <fstream>
#include <stdexcept>

#include "common/error.h"
#include "common/numbers.h"
#include "sensors/builtin_profiles.h"
#include "sensors/profile_file.h"
#include "sensors/sensor_profile.h"
#include "test/support/test_support.h"

namespace kestrel::sensors {
namespace {

TEST(BuiltinProfiles, EveryShippedFileParsesAndTheDefaultSetsNothing) {
  ASSERT_EQ(builtin_profile_names(), (std::vector<std::string>{"default", "kinect1", "simulator"}));
  const auto sets_anything = [](const SensorProfile& p) {
    return p.timing.rolling_shutter_readout_s || p.timing.depth_time_from_stamps || p.timing.depth_extra_latency_s ||
           p.vo.translation_floor_m || p.vo.rotation_floor_rad || p.vo.translation_per_rad_m ||
           p.vo.rotation_per_rad || p.vo.dense_weight || p.vo.min_inliers_to_keep_near || p.vo.floor_cap_fraction ||
           p.slam.loop_rotation_floor_rad;
  };
  EXPECT_FALSE(sets_anything(builtin_profile("default")));
  // The simulator's camera: a global shutter (no timing), the defaults fitted on its frames,
  // and the keyframe floors' cap measured on its bare corridors.
  SensorProfile sim = builtin_profile("simulator");
  EXPECT_EQ(sim.vo.floor_cap_fraction, 0.7);
  sim.vo.floor_cap_fraction.reset();
  EXPECT_FALSE(sets_anything(sim)) << "the simulator's profile sets only the cap";
  const SensorProfile& kinect = builtin_profile("kinect1");
  EXPECT_EQ(kinect.timing.rolling_shutter_readout_s, 0.015);
  EXPECT_EQ(kinect.timing.depth_time_from_stamps, true);
  EXPECT_EQ(kinect.timing.depth_extra_latency_s, 0.015);
  EXPECT_EQ(kinect.vo.min_inliers_to_keep_near, 150);
  EXPECT_EQ(kinect.slam.loop_rotation_floor_rad, kPi / 180.0);  // 1 degree
  EXPECT_THROW(builtin_profile("kinect2"), std::invalid_argument);
}

TEST(BuiltinProfiles, AFramesSensorModelNamesItsProfile) {
  EXPECT_EQ(profile_of_sensor("kinect1").name, "kinect1");
  EXPECT_EQ(profile_of_sensor("simulator").name, "simulator");
  EXPECT_EQ(profile_of_sensor("").name, "default");  // unknown: the built-in defaults
  EXPECT_EQ(profile_of_sensor("realsense_d435").name, "default");
}

TEST(ParseSensorProfile, AMinimalAndAFullProfile) {
  const SensorProfile minimal = parse_sensor_profile("name: cam_2\n", "t");
  EXPECT_EQ(minimal.name, "cam_2");
  EXPECT_FALSE(minimal.timing.rolling_shutter_readout_s.has_value());
  const SensorProfile full = parse_sensor_profile(
      "name: my-cam\ndescription: a test\ntiming: {rolling_shutter_readout_s: 0.03, depth_time_from_stamps: false, "
      "depth_extra_latency_s: -0.002}\nvo: {translation_floor_m: 0.002, rotation_floor_rad: 0.001, "
      "translation_per_rad_m: 0.2, rotation_per_rad: 0.05, dense_weight: 1, min_inliers_to_keep_near: 80, "
      "floor_cap_fraction: 0.5}\n"
      "slam: {loop_rotation_floor_deg: 2}\n",
      "t");
  EXPECT_EQ(full.description, "a test");
  EXPECT_EQ(full.timing.rolling_shutter_readout_s, 0.03);
  EXPECT_EQ(full.timing.depth_time_from_stamps, false);
  EXPECT_EQ(full.timing.depth_extra_latency_s, -0.002);
  EXPECT_EQ(full.vo.rotation_per_rad, 0.05);
  EXPECT_EQ(full.vo.min_inliers_to_keep_near, 80);
  EXPECT_EQ(full.vo.floor_cap_fraction, 0.5);
  EXPECT_DOUBLE_EQ(*full.slam.loop_rotation_floor_rad, 2.0 * kPi / 180.0);
}

// Each bad file, and the words its error must hold (the field it is about).
TEST(ParseSensorProfile, EveryKindOfBadFileIsRefusedNamingTheField) {
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"", "must be a map"},
      {"- a\n- b\n", "must be a map"},
      {"name: [unclosed\n", "not a sensor profile"},
      {"description: no name\n", "no 'name'"},
      {"name: \"\"\n", "'name' is empty"},
      {"name: Kinect 2\n", "only lower-case"},
      {"name: a\ncolour: red\n", "unknown field 'colour'"},
      {"name: a\ntiming: {readout: 0.01}\n", "unknown field 'timing.readout'"},
      {"name: a\ntiming: 0.01\n", "'timing' must be a map"},
      {"name: a\ntiming: {rolling_shutter_readout_s: fast}\n", "'timing.rolling_shutter_readout_s' is not a number"},
      {"name: a\ntiming: {rolling_shutter_readout_s: .nan}\n", "timing.rolling_shutter_readout_s"},
      {"name: a\ntiming: {rolling_shutter_readout_s: .inf}\n", "timing.rolling_shutter_readout_s"},
      {"name: a\ntiming: {rolling_shutter_readout_s: -0.01}\n", "must be in"},
      {"name: a\ntiming: {depth_extra_latency_s: 2}\n", "timing.depth_extra_latency_s"},
      {"name: a\ntiming: {depth_time_from_stamps: maybe}\n", "not true or false"},
      {"name: a\nvo: {translation_floor_m: -1}\n", "vo.translation_floor_m"},
      {"name: a\nvo: {min_inliers_to_keep_near: 1.5}\n", "whole number"},
      {"name: a\nvo: {floor_cap_fraction: 1.5}\n", "vo.floor_cap_fraction"},
      {"name: a\nvo: {floor_cap_fraction: -0.5}\n", "vo.floor_cap_fraction"},
      {"name: a\nslam: {loop_rotation_floor_deg: 90}\n", "slam.loop_rotation_floor_deg"},
      {"name: {x: 1}\n", "'name' is not a word"},
      {"name:\n", "'name' is not a word"},  // YAML's null, not a profile called "null"
      {"name: a\ndescription: [x]\n", "'description' is not a line of text"},
      {"name: a\nname: b\n", "field 'name' is given twice"},
      {"name: a\nvo: {dense_weight: 1, dense_weight: 2}\n", "field 'vo.dense_weight' is given twice"},
      {"name: a\n---\nname: b\n", "holds 2 YAML documents"},
      {"name: a\ntiming: {rolling_shutter_readout_s: 0.1}\n", "must be in [0, 0.1)"},  // the VO's bound
      {"name: a\ntiming: {depth_extra_latency_s: -0.1}\n", "must be in (-0.1, 0.1)"},
  };
  for (const auto& [text, words] : cases) {
    try {
      parse_sensor_profile(text, "my.yaml");
      ADD_FAILURE() << "accepted:\n" << text;
    } catch (const std::invalid_argument& e) {
      const std::string what = e.what();
      EXPECT_EQ(what.rfind("my.yaml: ", 0), 0u) << what;
      EXPECT_NE(what.find(words), std::string::npos) << "'" << words << "' not in: " << what;
    }
  }
}

TEST(LoadSensorProfile, ByNameOrByFile) {
  test::TempDir dir;
  EXPECT_EQ(load_sensor_profile("kinect1").name, "kinect1");
  const std::string good = (dir / "cam.yaml").string();
  std::ofstream(good) << "name: cam\nvo: {dense_weight: 3}\n";
  EXPECT_EQ(load_sensor_profile(good).vo.dense_weight, 3.0);
  EXPECT_EQ(check_sensor_profile_name(good), "");
  const std::string bad = (dir / "bad.yaml").string();
  std::ofstream(bad) << "name: cam\nvo: {dense_weight: heavy}\n";
  EXPECT_THROW(load_sensor_profile(bad), InputError);  // a file that is not a profile: bad input
  const std::string missing = (dir / "none.yaml").string();
  EXPECT_THROW(load_sensor_profile(missing), std::invalid_argument);
  EXPECT_NE(check_sensor_profile_name(missing).find("kinect1, simulator"), std::string::npos)
      << "the error names the built-in profiles";
  EXPECT_NE(check_sensor_profile_name(dir.path().string()), "");  // a folder is not a profile
}

}  // namespace
}  // namespace kestrel::sensors
