// kestrel-monitor: a terminal view of the LCM traffic. Subscribes to every channel, checks
// each message against its channel's kestrel type (message_types.h), and shows per channel
// the count, rate, bandwidth and decode failures; --json prints a summary on exit.

#include <glib.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <csignal>
#include <iostream>
#include <lcm/lcm-cpp.hpp>

#include "common/interrupt.h"
#include "common/cli.h"
#include "common/error.h"
#include "common/transport/lcm_url.h"
#include "tools/monitor/traffic.h"

namespace {


double now_s() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Options {
  std::string lcm_url;
  std::string channels = ".*";
  double duration_s = 0.0;
  int64_t count = 0;
  double period_s = 1.0;
  bool json = false;
  std::vector<std::string> types;
};

struct Receiver {
  kestrel::monitor::TrafficMonitor* traffic;
  std::map<std::string, int64_t> logged;  // failures logged per channel
  static void on(const lcm::ReceiveBuffer* rbuf, const std::string& channel, Receiver* self) {
    const std::string error = self->traffic->on_message(channel, rbuf->data, rbuf->data_size, now_s());
    // The first few failures per channel, then one in a hundred: the counts stay exact.
    if (!error.empty()) {
      const int64_t n = ++self->logged[channel];
      if (n <= 5 || n % 100 == 0) spdlog::warn("decode failure #{}: {}", n, error);
    }
  }
};

int monitor(const Options& o) {
  auto channel_types = kestrel::monitor::default_channel_types();
  for (const auto& spec : o.types) {
    try {
      const auto [channel, type] = kestrel::monitor::parse_channel_type(spec);
      channel_types[channel] = type;
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError("--type", e.what());
    }
  }
  const std::string url = kestrel::transport::resolve_lcm_url(o.lcm_url);
  lcm::LCM lcm(url);
  if (!lcm.good()) {
    spdlog::error("cannot start LCM on '{}'", url);
    return kestrel::kExitUnavailable;
  }
  kestrel::monitor::TrafficMonitor traffic(channel_types);
  Receiver receiver{&traffic, {}};
  // LCM anchors the pattern and compiles it with GLib; on failure its C++ API still returns a
  // subscription, which then crashes on first use. So the same compile is tried here first.
  GError* regex_error = nullptr;
  GRegex* regex = g_regex_new(("^" + o.channels + "$").c_str(), static_cast<GRegexCompileFlags>(0),
                              static_cast<GRegexMatchFlags>(0), &regex_error);
  if (regex == nullptr) {
    const std::string why = regex_error != nullptr ? regex_error->message : "does not compile";
    g_clear_error(&regex_error);
    throw CLI::ValidationError("--channels", "'" + o.channels + "' is not a regular expression LCM takes (" +
                                                 kestrel::cli::printable(why) + ")");
  }
  g_regex_unref(regex);
  lcm::Subscription* subscription = lcm.subscribeFunction(o.channels, &Receiver::on, &receiver);
  if (subscription == nullptr)
    throw CLI::ValidationError("--channels", "'" + o.channels + "' is not a regular expression LCM takes");
  subscription->setQueueCapacity(0);
  kestrel::catch_interrupts();
  spdlog::info("listening on {} (channels {})", url, o.channels);

  // Periodic tables go to stdout, or to stderr when stdout carries the JSON summary.
  std::ostream& view = o.json ? std::cerr : std::cout;
  const bool tty = ::isatty(o.json ? 2 : 1) != 0;
  const double start = now_s();
  double next_table = start + o.period_s;
  while (!kestrel::interrupted()) {
    const double t = now_s();
    if (o.duration_s > 0.0 && t - start >= o.duration_s) break;
    if (o.count > 0 && traffic.total() >= o.count) break;
    if (o.period_s > 0.0 && t >= next_table) {
      view << (tty ? "\033[H\033[2J" : "\n") << traffic.table(t) << std::flush;
      next_table += o.period_s;
    }
    lcm.handleTimeout(50);
  }
  const double elapsed = now_s() - start;
  if (o.json) {
    std::cout << traffic.summary(elapsed).dump(2) << "\n";
  } else {
    std::cout << "\n" << traffic.total() << " messages in " << elapsed << " s, "
              << traffic.failures() << " decode failures\n"
              << traffic.table(now_s());
  }
  if (traffic.failures() == 0) return kestrel::kExitOk;
  std::string which;
  for (const auto& [channel, s] : traffic.channels())
    if (s.failures > 0) which += (which.empty() ? "" : ", ") + channel + " (" + std::to_string(s.failures) + ")";
  spdlog::error("messages that do not decode as their channel's type: {}", which);
  return kestrel::kExitBadInput;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app("monitor",
                        "Shows the LCM traffic per channel: count, rate, bandwidth, and messages "
                        "that do not decode as the channel's kestrel type. Exit status 3 if any "
                        "did not.");
  Options o;
  app.add_option("--lcm-url", o.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  app.add_option("--channels", o.channels, "LCM regex of the channels to watch")->capture_default_str();
  app.add_option("--duration", o.duration_s, "Stop after this many seconds (0 = at Ctrl-C)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--count", o.count, "Stop after this many messages (0 = no limit)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--period", o.period_s, "Seconds between tables (0 = only at the end)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--type", o.types,
                 "CHANNEL=TYPE: check CHANNEL as this kestrel type (repeatable); other unnamed "
                 "channels are identified by fingerprint");
  app.add_flag("--json", o.json, "Print a JSON summary on exit (tables go to stderr)");
  return app.run(argc, argv, [&] { return monitor(o); });
}
