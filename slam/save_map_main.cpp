// kestrel save-map: asks a running kestrel-slam to save its SLAM map now (into its --save-map
// folder) and waits for its answer in the heartbeat. Exit 0 when saved, 1 when it said it could
// not or did not answer within --timeout, 4 when LCM is unavailable.

#include <spdlog/spdlog.h>

#include <chrono>
#include <iostream>
#include <string>

#include "common/cli.h"
#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/node.h"
#include "kestrel/map_save_request_t.hpp"
#include "kestrel/process_status_t.hpp"

namespace {

using namespace kestrel;

struct Options {
  std::string process = "slam";
  std::string lcm_url;
  double timeout_s = 10.0;
};

int run(const Options& o) {
  transport::Node node("save-map", o.lcm_url);  // UnavailableError: exit 4
  node.advertise(channel::kSlamSaveMap);
  const int64_t id =
      std::chrono::duration_cast<std::chrono::microseconds>(std::chrono::system_clock::now().time_since_epoch()).count();
  const std::string saved = "map saved for request " + std::to_string(id) + ":";
  const std::string not_saved = "map not saved for request " + std::to_string(id) + ":";
  std::string answer;
  bool heard = false;
  node.subscribe<process_status_t>(channel::kProcessStatus, [&](const process_status_t& m) {
    if (m.name != o.process) return;
    heard = true;
    if (m.message.rfind(saved, 0) == 0 || m.message.rfind(not_saved, 0) == 0) answer = m.message;
  });
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  double sent_at = -1.0;
  while (answer.empty() && elapsed() < o.timeout_s && node.spin_once(100)) {
    // Asked again every 2 s until answered: a request sent before the process listened is lost.
    if (sent_at < 0.0 || elapsed() - sent_at > 2.0) {
      map_save_request_t r{};
      r.utime = id;
      r.request_id = id;
      node.publish(channel::kSlamSaveMap, r);
      sent_at = elapsed();
    }
  }
  if (answer.empty()) {
    std::cerr << "save-map: no answer from " << o.process << " within " << o.timeout_s << " s"
              << (heard ? " (it runs: was it started with --save-map?)" : " (no heartbeat from it)") << "\n";
    return kExitFailure;
  }
  std::cout << answer << "\n";
  return answer.rfind(saved, 0) == 0 ? kExitOk : kExitFailure;
}

}  // namespace

int main(int argc, char** argv) {
  cli::App app("save-map", "Ask a running kestrel-slam to save its SLAM map now (into its --save-map folder)");
  Options o;
  app.add_option("--process", o.process, "Name of the SLAM process (its heartbeats)")->capture_default_str();
  app.add_option("--timeout", o.timeout_s, "Seconds to wait for its answer")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--lcm-url", o.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  return app.run(argc, argv, [&] { return run(o); });
}
