// kestrel-station: the ground station in a browser. Listens to the bus (STATE, GROUND_TRUTH,
// SLAM_GRAPH, PLAN, MAP_OCTOMAP, CAMERA_RGBD, PROCESS_STATUS, PLAYBACK_STATUS and every
// channel's rate) and serves one page over HTTP + WebSocket that draws them live; the page's
// goals go out as PLAN_REQUEST, its hold as a PLAN without a path, and its transport bar (a
// replay under review) as PLAYBACK_COMMAND. The logic is Station (station.h), the
// server WebServer (web_server.h); this file wires them to a Node.
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <random>
#include <string>

#include "common/cli.h"
#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/node.h"
#include "station/station.h"
#include "station/web_server.h"

namespace {

using namespace kestrel;

struct Options {
  std::string name = "station";
  std::string lcm_url;
  station::WebServerOptions web;
  station::StationOptions station;
};

double steady_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

// The page's files beside the executable: <build>/bin/kestrel-tools -> <build>/share/kestrel/station.
std::string default_web_root() {
  std::error_code ec;
  const std::filesystem::path exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (ec) return "share/kestrel/station";
  return (exe.parent_path().parent_path() / "share" / "kestrel" / "station").string();
}

// 128 random bits as hex, from the kernel's generator.
std::string new_token() {
  std::random_device device;
  std::string token;
  for (int i = 0; i < 4; ++i) {
    char word[9];
    std::snprintf(word, sizeof word, "%08x", static_cast<unsigned>(device()));
    token += word;
  }
  return token;
}

int serve(Options& o) {
  o.station.validate();
  if (o.web.document_root.empty()) o.web.document_root = default_web_root();
  if (!std::filesystem::exists(std::filesystem::path(o.web.document_root) / "index.html"))
    throw InputError(o.web.document_root + ": no index.html (the page is copied there by the build; --web-root)");
  if (!station::is_loopback(o.web.bind)) o.web.token = o.station.token = new_token();

  station::UpdateHub hub(o.web.max_clients);
  const int64_t first_request_id =
      std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  station::Station st(o.station, hub, first_request_id);

  transport::Node node(o.name, o.lcm_url);  // UnavailableError: exit 4
  node.advertise(channel::kPlanRequest);
  node.advertise(channel::kPlan);
  node.advertise(channel::kPlaybackCommand);
  node.on_reset([&] { st.reset(); });
  // A viewer: short queues everywhere, so that a busy station loses messages rather than
  // memory or time (LCM drops the oldest).
  node.subscribe<state_t>(channel::kState, [&](const state_t& m) { st.on_state(m, channel::kState); }, 30);
  node.subscribe<ground_truth_t>(channel::kGroundTruth, [&](const ground_truth_t& m) { st.on_truth(m, channel::kGroundTruth); }, 30);
  node.subscribe<slam_graph_t>(channel::kSlamGraph, [&](const slam_graph_t& m) { st.on_graph(m, channel::kSlamGraph); }, 4);
  node.subscribe<plan_t>(channel::kPlan, [&](const plan_t& m) { st.on_plan(m, channel::kPlan); }, 8);
  node.subscribe<plan_covariance_t>(channel::kPlanCovariance,
                                    [&](const plan_covariance_t& m) { st.on_plan_covariance(m, channel::kPlanCovariance); }, 8);
  node.subscribe<octomap_t>(channel::kMapOctomap, [&](const octomap_t& m) { st.on_map(m, channel::kMapOctomap); }, 2);
  node.subscribe<rgbd_frame_t>(channel::kCameraRgbd, [&](const rgbd_frame_t& m) { st.on_frame(m, channel::kCameraRgbd); }, 2);
  node.subscribe<playback_status_t>(channel::kPlaybackStatus,
                                    [&](const playback_status_t& m) { st.on_playback(m, channel::kPlaybackStatus); }, 8);
  // Every channel's traffic for the rates, and the heartbeats for the health table, straight
  // from LCM rather than through the Node: they are telemetry, not inputs, so under lock-step
  // replay they must not be acknowledged (an acknowledgement of a heartbeat stalls the replay).
  struct Counter {
    station::Station* st;
    int64_t bad_heartbeats = 0;
    static void on(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Counter* self) {
      self->st->on_traffic(channel, rbuf->data_size);
      if (channel != channel::kProcessStatus) return;
      try {
        self->st->on_status(transport::decode_message<process_status_t>(rbuf->data, rbuf->data_size, channel::kProcessStatus),
                            steady_s());
      } catch (const InputError& e) {
        if (++self->bad_heartbeats <= 5) spdlog::warn("{}", e.what());
      }
    }
  } counter{&st};
  lcm::Subscription* all = node.lcm().subscribeFunction(".*", &Counter::on, &counter);
  // Every message waits here too, camera frames included (1.5 MB raw): a short queue bounds
  // what a stalled station holds; a rate counted short then is the price.
  if (all) all->setQueueCapacity(64);

  station::WebServer server(o.web, hub);
  const std::string url = "http://" + (o.web.bind.find(':') != std::string::npos ? "[" + o.web.bind + "]" : o.web.bind) +
                          ":" + std::to_string(server.port()) + "/" + (o.web.token.empty() ? "" : "?token=" + o.web.token);
  // The address on stdout (a script or test reads it), the rest in the log.
  std::printf("%s\n", url.c_str());
  std::fflush(stdout);
  spdlog::info("{}: serving {} from {}{}", o.name, url, o.web.document_root,
               o.web.token.empty() ? "" : " (not loopback: the token in the address is required)");
  node.set_health(process_status_t::STATE_RUNNING, "");

  double next_periodic_s = 0.0;
  int64_t requests = 0, holds = 0, transport = 0, refused = 0;
  while (node.spin_once(50)) {
    for (auto& [client, text] : server.take_commands()) {
      const station::CommandResult r = st.on_command(client, text);
      if (r.request) {
        node.publish(channel::kPlanRequest, *r.request);
        ++requests;
      }
      if (r.hold) {
        node.publish(channel::kPlan, *r.hold);
        ++holds;
      }
      if (r.playback) {
        playback_command_t command = *r.playback;
        command.utime = std::chrono::duration_cast<std::chrono::microseconds>(
                            std::chrono::system_clock::now().time_since_epoch())
                            .count();
        node.publish(channel::kPlaybackCommand, command);
        ++transport;
      }
      if (!r.ok) ++refused;
      spdlog::info("page: {}", cli::printable(r.notice));
    }
    const double now = steady_s();
    if (now >= next_periodic_s) {
      st.post_periodic(now);
      next_periodic_s = now + 1.0;
    }
  }
  const auto stats = hub.stats();
  spdlog::info("{} requests, {} holds, {} replay commands, {} commands refused; {} updates sent, {} replaced before "
               "sending (slow browsers)",
               requests, holds, transport, refused, stats.taken, stats.dropped);
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  cli::App app("station", "Ground station in the browser: the map, the vehicle, the plan, images, health; click to fly");
  Options o;
  app.add_option("--name", o.name, "Process name in heartbeats")->capture_default_str();
  app.add_option("--lcm-url", o.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  app.add_option("--bind", o.web.bind, "Address to serve on; not a loopback one: a token is required (printed at start)")
      ->capture_default_str();
  app.add_option("--port", o.web.port, "HTTP and WebSocket port (0: any free one, printed at start)")
      ->check(CLI::Range(0, 65535))
      ->capture_default_str();
  app.add_option("--web-root", o.web.document_root, "The page's files (default: <build>/share/kestrel/station)");
  app.add_option("--max-clients", o.web.max_clients, "Browsers served at once")->check(CLI::Range(1, 64))->capture_default_str();
  app.add_option("--state-period", o.station.state_period_s, "STATE to the page at most this often (s of sensor time)")
      ->check(cli::Positive)->capture_default_str();
  app.add_option("--image-period", o.station.preview.period_s, "Camera images to the page at most this often (s of sensor time)")
      ->check(cli::Positive)->capture_default_str();
  app.add_option("--jpeg-quality", o.station.preview.jpeg_quality, "JPEG quality of the images (1..100)")
      ->check(CLI::Range(1, 100))->capture_default_str();
  app.add_option("--goal-clearance", o.station.goal.clearance_m, "A goal nearer than this to an occupied cell is refused (m)")
      ->check(CLI::Range(0.0, 2.0))->capture_default_str();
  return app.run(argc, argv, [&] { return serve(o); });
}
