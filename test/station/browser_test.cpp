// The station's page in a real browser on a replayed flight: Debian's chromium, headless,
// driven by puppeteer-core (check.js) while this test runs the processes in a private network
// and judges what the page showed against what the processes published:
//  * the page's map holds exactly the occupied cells of the mapper's last MAP_OCTOMAP;
//  * the vehicle marker is at the pose of the STATE the test published;
//  * the health table lists every process heard on PROCESS_STATUS;
//  * the colour and depth images arrive and decode at the camera's size;
//  * a goal outside the map is refused with a message in the page, and nothing is sent;
//  * a click on the map sends a PLAN_REQUEST that appears on LCM with the clicked point;
//  * a replay's PLAYBACK_STATUS shows the transport bar, whose pause button sends a
//    PLAYBACK_COMMAND (the replay's side: test/replay/playback_test.cpp);
//  * the screenshot's canvas is not blank.
// Under CI=true, a missing chromium, node or puppeteer-core fails the test instead of skipping.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>
#include <lcm/lcm-cpp.hpp>
#include <set>

#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/lcm_url.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/octomap_t.hpp"
#include "kestrel/plan_request_t.hpp"
#include "kestrel/playback_command_t.hpp"
#include "kestrel/playback_status_t.hpp"
#include "kestrel/state_t.hpp"
#include "mapper/octree_io.h"
#include "test/support/live_system.h"

namespace kestrel {
namespace {

namespace fs = std::filesystem;

std::string csv(const Eigen::Vector3d& p) {
  return std::to_string(p.x()) + "," + std::to_string(p.y()) + "," + std::to_string(p.z());
}

// Why the browser cannot run here ("" if it can).
std::string browser_missing() {
  if (!fs::exists(KESTREL_CHROMIUM)) return std::string(KESTREL_CHROMIUM) + " is missing (apt-get install chromium)";
  if (!fs::exists(fs::path(KESTREL_NPM_DIR) / "node_modules" / "puppeteer-core"))
    return std::string("puppeteer-core is not installed in ") + KESTREL_NPM_DIR + " (./kestrel test installs it)";
  if (test::run({"node", "--version"}, 10.0).exit_code != 0) return "node is missing";
  return "";
}

TEST(StationBrowser, ThePageShowsTheFlightAndAClickSendsAPlanRequest) {
  if (const std::string why = test::LiveSystem::isolate(); !why.empty()) KESTREL_SKIP_ENVIRONMENT() << why;
  if (const std::string why = browser_missing(); !why.empty()) KESTREL_SKIP_ENVIRONMENT() << why;
  test::TempDir dir;
  const fs::path source = dir / "source.lcmlog";
  // 3 s of the figure-eight in the room: about 90 frames, a map of a few thousand cells.
  const auto sim = test::run({test::tool("sim").string(), "--world", "room", "--flight", "figure8", "--duration", "3",
                              "--seed", "1", "--log", source.string(), "-q"}, 120.0);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;

  test::LiveSystem::Options options;
  options.channels = {channel::kMapOctomap, channel::kPlanRequest, channel::kGroundTruth, channel::kPlaybackCommand};
  test::LiveSystem sys(dir.path(), options);
  sys.start("mapper", {test::tool("mapper").string(), "--pose-source", "ground-truth", "--publish-period", "0.5"});
  sys.start("station", {test::tool("station").string(), "--port", "8765"});
  ASSERT_NE(sys.wait_running("mapper"), 0);
  ASSERT_NE(sys.wait_running("station"), 0) << sys.output("station");
  ASSERT_EQ(sys.replay(source, "mapper,station", dir / "out.lcmlog"), 0) << sys.output("replay");

  // What the mapper published last, as the mapper's own reader counts it.
  const auto maps = sys.messages(channel::kMapOctomap);
  ASSERT_FALSE(maps.empty());
  const auto last = transport::decode_message<kestrel::octomap_t>(maps.back().data.data(), maps.back().data.size(), "MAP");
  const size_t occupied = mapper::decode_octree(last.data.data(), last.data.size(), mapper::OctreeFormat::kBinary, "MAP")
                              .num_occupied();
  ASSERT_GT(occupied, 100u);

  // A STATE at a known pose, published by the test.
  lcm::LCM lcm(transport::resolve_lcm_url(""));
  ASSERT_TRUE(lcm.good());
  kestrel::state_t state{};
  state.utime = last.utime + 1000;
  state.status = kestrel::state_t::STATUS_OK;
  const Eigen::Vector3d p_vehicle(0.3, -0.2, 1.1);
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
  T_world_body.linear() = Eigen::AngleAxisd(0.4, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_world_body.translation() = p_vehicle;
  state.T_world_body = transport::to_message(T_world_body);
  state.cov_dim = 15;
  state.covariance.assign(15, std::vector<double>(15, 0.0));
  for (size_t i = 0; i < 15; ++i) state.covariance[i][i] = 1e-3;
  lcm.publish(channel::kState, &state);
  // A controlled replay's status, as `kestrel replay LOG --control` says it: 20 s of log, at 5 s.
  kestrel::playback_status_t playback{};
  playback.start_utime = 1'000'000;
  playback.end_utime = 21'000'000;
  playback.utime = 6'000'000;
  playback.speed = 1.0;
  playback.log_name = "flight.lcmlog";
  lcm.publish(channel::kPlaybackStatus, &playback);

  // The goal: where the vehicle truly was mid-flight (free space the camera saw around it).
  const auto truths = sys.messages(channel::kGroundTruth);
  ASSERT_FALSE(truths.empty());
  const auto& mid = truths[truths.size() / 2];
  const auto truth = transport::decode_message<kestrel::ground_truth_t>(mid.data.data(), mid.data.size(), "GT");
  const Eigen::Vector3d goal = transport::from_message(truth.T_world_frame, "GT").translation();

  std::set<std::string> processes;
  for (const auto& m : sys.messages(channel::kProcessStatus))
    processes.insert(transport::decode_message<kestrel::process_status_t>(m.data.data(), m.data.size(), "PS").name);
  std::string names;
  for (const auto& n : processes) names += (names.empty() ? "" : ",") + n;

  const size_t requests_before = sys.messages(channel::kPlanRequest).size();
  const fs::path result_path = dir / "result.json";
  const fs::path screenshot = fs::path(KESTREL_BINARY_DIR) / "station-browser-test.png";
  const int browser = sys.run("browser",
                              {"env", std::string("NODE_PATH=") + KESTREL_NPM_DIR + "/node_modules", "node",
                               (test::source_dir() / "test/station/browser/check.js").string(), "--url",
                               "http://127.0.0.1:8765/", "--out", result_path.string(), "--screenshot",
                               screenshot.string(), "--cells", std::to_string(occupied), "--vehicle", csv(p_vehicle),
                               "--processes", names, "--goal", csv(goal), "--refused-goal", "100,100,1", "--playback-length", "20", "--chromium",
                               KESTREL_CHROMIUM},
                              90.0);
  ASSERT_EQ(browser, 0) << sys.output("browser");
  const nlohmann::json r = nlohmann::json::parse(test::read_file(result_path));
  ASSERT_FALSE(r.contains("error")) << r.dump(1);
  EXPECT_TRUE(r["webgl"].get<bool>()) << "no WebGL in headless chromium";

  EXPECT_EQ(r["cells"].get<size_t>(), occupied) << "the page's map differs from the mapper's";
  ASSERT_TRUE(r["vehicle"].is_array()) << r.dump(1);
  EXPECT_NEAR(r["vehicle"][0].get<double>(), p_vehicle.x(), 1e-6);
  EXPECT_NEAR(r["vehicle"][1].get<double>(), p_vehicle.y(), 1e-6);
  EXPECT_NEAR(r["vehicle"][2].get<double>(), p_vehicle.z(), 1e-6);
  for (const auto& n : processes) {
    const auto& listed = r["health_names"];
    EXPECT_NE(std::find(listed.begin(), listed.end(), n), listed.end()) << n << " is not in the health table";
  }
  EXPECT_GE(r["health_rows"].get<size_t>(), processes.size());
  // The camera's images, decoded by the browser at the simulator's 640 x 480.
  EXPECT_EQ(r["images"], nlohmann::json::parse("[[640,480],[640,480]]")) << r["images"].dump();

  ASSERT_TRUE(r["refused_notice"].is_object()) << r.dump(1);
  EXPECT_FALSE(r["refused_notice"]["ok"].get<bool>());
  EXPECT_NE(r["refused_notice"]["text"].get<std::string>().find("outside the map"), std::string::npos)
      << r["refused_notice"].dump();

  ASSERT_TRUE(r["click_notice"].is_object()) << r.dump(1);
  EXPECT_TRUE(r["click_notice"]["ok"].get<bool>()) << r["click_notice"].dump();
  // The request on the bus: the clicked point (the page's reading of the pixel: within a
  // pixel's footprint, 2 cm here) at the typed height, and exactly what the page showed.
  const auto request = sys.wait_for<kestrel::plan_request_t>(
      channel::kPlanRequest, [](const kestrel::plan_request_t&) { return true; }, 10.0, "the click's PLAN_REQUEST",
      0);
  ASSERT_TRUE(request.has_value());
  EXPECT_EQ(sys.messages(channel::kPlanRequest).size(), requests_before + 1) << "the refused goal must send nothing";
  EXPECT_NEAR(request->goal[0], goal.x(), 0.02);
  EXPECT_NEAR(request->goal[1], goal.y(), 0.02);
  EXPECT_NEAR(request->goal[2], goal.z(), 1e-3);
  EXPECT_NEAR(request->goal[0], r["goal_fields"][0].get<double>(), 1e-9);
  EXPECT_NEAR(request->goal[1], r["goal_fields"][1].get<double>(), 1e-9);
  EXPECT_EQ(request->start_mode, kestrel::plan_request_t::START_FROM_STATE);

  // The transport bar: where the replay is, and its pause on the bus.
  ASSERT_TRUE(r["playback"].is_object()) << r.dump(1);
  EXPECT_DOUBLE_EQ(r["playback"]["t"].get<double>(), 5.0);
  EXPECT_DOUBLE_EQ(r["playback"]["length"].get<double>(), 20.0);
  EXPECT_TRUE(r["pause_notice"]["ok"].get<bool>()) << r["pause_notice"].dump();
  const auto pause = sys.wait_for<kestrel::playback_command_t>(
      channel::kPlaybackCommand, [](const kestrel::playback_command_t&) { return true; }, 10.0, "the pause", 0);
  ASSERT_TRUE(pause.has_value());
  EXPECT_EQ(pause->command, kestrel::playback_command_t::COMMAND_PAUSE);

  // Not a blank canvas: the cells and the vehicle cover part of it in many colours.
  EXPECT_GT(r["canvas"]["non_background"].get<double>(), 0.01) << r["canvas"].dump();
  EXPECT_GT(r["canvas"]["colours"].get<int>(), 20) << r["canvas"].dump();
  EXPECT_TRUE(fs::exists(screenshot));
}

}  // namespace
}  // namespace kestrel
