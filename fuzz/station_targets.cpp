// The ground station's outside input: the page's commands (text off a WebSocket, from any
// browser that reaches it), and the messages it turns into the page's updates with its own
// code (STATE, PLAN, SLAM_GRAPH, GROUND_TRUTH, MAP_OCTOMAP, CAMERA_RGBD) after the Node's
// decoding. Built when station/ is (KESTREL_FUZZ_STATION).

#include <Eigen/Geometry>

#include "common/transport/convert.h"
#include "common/transport/message.h"
#include "fuzz/examples.h"
#include "fuzz/groups.h"
#include "station/station.h"

namespace kestrel::fuzz {
namespace {

using transport::decode_message;
using transport::encode_message;

// A map with one occupied cell at (1.05, 0.05, 1.05) inside bounds (-2,-2,0)..(2,2,2.5).
const station::CellSet& command_map() {
  static const station::CellSet map = [] {
    station::CellSet m;
    m.resolution_m = 0.1;
    m.known_bounds = Eigen::AlignedBox3d(Eigen::Vector3d(-2, -2, 0), Eigen::Vector3d(2, 2, 2.5));
    m.ids = {32778ull | (32768ull << 16) | (32778ull << 32)};
    m.cells = {{1.05f, 0.05f, 1.05f, 0.1f}};
    return m;
  }();
  return map;
}

// A command is parsed with a token required, then checked against the map. Refusals are
// CommandError (the page's message), which is the accepted way for a command to fail.
bool run_command(const uint8_t* data, size_t size) {
  try {
    const station::Command c =
        station::parse_command(std::string_view(reinterpret_cast<const char*>(data), size), "0123456789abcdef");
    if (const auto* p = std::get_if<station::PlaybackCommand>(&c)) {
      // Against a replay of 20 s: what is sent lies within its log, at a speed it can play.
      kestrel::playback_status_t replay{};
      replay.start_utime = 1'000'000;
      replay.end_utime = 21'000'000;
      replay.speed = 1.0;
      std::string refusal;
      const kestrel::playback_command_t m = station::playback_command(*p, replay, 1, refusal);
      if (refusal.empty() && m.command == kestrel::playback_command_t::COMMAND_SEEK &&
          (m.seek_utime < replay.start_utime || m.seek_utime > replay.end_utime))
        defect("station-command", "an accepted seek lies outside the log");
      if (m.command == kestrel::playback_command_t::COMMAND_SPEED &&
          !(m.speed > 0.0 && m.speed <= station::kMaxPlaybackSpeed))
        defect("station-command", "an accepted speed is not one the replay can play");
    }
    if (const auto* g = std::get_if<station::GoalCommand>(&c)) {
      const std::string why = station::check_goal(*g, &command_map(), {});
      if (why.empty()) {
        const kestrel::plan_request_t r = station::plan_request(*g, 1, 0);
        for (double v : r.goal)
          if (!std::isfinite(v)) defect("station-command", "an accepted goal is not finite");
      }
    }
    return true;
  } catch (const station::CommandError&) {
    return false;
  }
}

std::vector<Bytes> command_seeds() {
  return {text(R"({"cmd":"goal","goal":[0,0,1,0],"token":"0123456789abcdef"})"),
          text(R"({"cmd":"hold","token":"0123456789abcdef"})"),
          text(R"({"token":"0123456789abcdef","cmd":"goal","goal":[-1.5,1.25,2.0,3.1]})"),
          text(R"({"cmd":"seek","t":12.5,"token":"0123456789abcdef"})"),
          text(R"({"cmd":"speed","speed":4,"token":"0123456789abcdef"})")};
}

// The first byte picks the message type, the rest is that message as LCM encodes it; the
// station converts it as its Node handler does. Refusals are InputError.
bool run_update(const uint8_t* data, size_t size) {
  if (size == 0) return false;
  static station::UpdateHub hub;
  static station::Station st({}, hub, 1);
  const uint8_t* m = data + 1;
  const size_t n = size - 1;
  return accepted([&] {
    switch (data[0] % 8) {
      case 0: st.on_state(decode_message<kestrel::state_t>(m, n, "STATE"), "STATE"); break;
      case 1: st.on_plan(decode_message<kestrel::plan_t>(m, n, "PLAN"), "PLAN"); break;
      case 2: st.on_graph(decode_message<kestrel::slam_graph_t>(m, n, "SLAM_GRAPH"), "SLAM_GRAPH"); break;
      case 3: st.on_truth(decode_message<kestrel::ground_truth_t>(m, n, "GROUND_TRUTH"), "GROUND_TRUTH"); break;
      case 4: st.on_map(decode_message<kestrel::octomap_t>(m, n, "MAP_OCTOMAP"), "MAP_OCTOMAP"); break;
      case 5: st.on_frame(decode_message<kestrel::rgbd_frame_t>(m, n, "CAMERA_RGBD"), "CAMERA_RGBD"); break;
      case 7:
        st.on_plan_covariance(decode_message<kestrel::plan_covariance_t>(m, n, "PLAN_COVARIANCE"), "PLAN_COVARIANCE");
        break;
      default:
        st.on_playback(decode_message<kestrel::playback_status_t>(m, n, "PLAYBACK_STATUS"), "PLAYBACK_STATUS");
        break;
    }
  });
}

template <class Msg>
Bytes tagged(uint8_t tag, const Msg& msg) {
  Bytes b = encode_message(msg);
  b.insert(b.begin(), tag);
  return b;
}

std::vector<Bytes> update_seeds() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.5, -0.25, 1.0);
  kestrel::state_t s{};
  s.utime = 1'000'000;
  s.status = kestrel::state_t::STATUS_OK;
  s.T_world_body = transport::to_message(T);
  s.cov_dim = 3;
  s.covariance = {{0.01, 0, 0}, {0, 0.02, 0}, {0, 0, 0.03}};
  kestrel::plan_t p{};
  p.status = kestrel::plan_t::STATUS_OK;
  p.num_waypoints = 2;
  p.waypoints = {{0, 0, 1, 0}, {1, 0, 1, 0}};
  p.covariance_trace = {0.01, 0.02};
  kestrel::slam_graph_t g{};
  g.keyframes = {keyframe(10, 0.0), keyframe(11, 0.3)};
  g.num_keyframes = 2;
  kestrel::ground_truth_t t{};
  t.T_world_frame = transport::to_message(T);
  kestrel::playback_status_t r{};
  r.start_utime = 1'000'000;
  r.end_utime = 21'000'000;
  r.utime = 6'000'000;
  r.speed = 1.0;
  r.log_name = "flight.lcmlog";
  kestrel::plan_covariance_t c{};  // the plan's (utime and request id 0)
  c.num_waypoints = 2;
  c.covariance = {std::vector<double>(16, 0.0), std::vector<double>(16, 0.0)};
  c.covariance[0][0] = c.covariance[0][5] = 0.01;
  c.covariance[1][0] = 0.04;
  c.covariance[1][5] = 0.01;
  return {tagged(0, s), tagged(1, p), tagged(2, g), tagged(3, t), tagged(6, r), tagged(7, c)};
}

}  // namespace

std::vector<Target> station_targets() {
  return {
      {"station-command", "a command from the station's page (JSON over its WebSocket)", &run_command, &command_seeds},
      {"station-updates", "a message the station draws (type by the first byte, then its LCM bytes)", &run_update,
       &update_seeds},
  };
}

}  // namespace kestrel::fuzz
