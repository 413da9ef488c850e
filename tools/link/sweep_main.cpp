// kestrel-link-sweep: flies the split system (tools/link/split_flight.h) once per loss rate
// over the emulated link and prints one Markdown table row per flight: the true deviation
// while holding, the corrections and plans that reached the vehicle, the mapper's keyframes
// and the datagrams the link dropped. The table in docs/reliability.md is its output.

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <filesystem>
#include <string>
#include <vector>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "common/error.h"
#include "tools/link/split_flight.h"

namespace {

namespace fs = std::filesystem;

struct Options {
  std::vector<double> losses = {0, 10, 30};
  std::string out;
  uint64_t seed = 1;
  double duration_s = 55;
  double delay_ms = 30, jitter_ms = 10, rate_mbit = 20;
  std::string json;
};

int sweep(const Options& o) {
  const fs::path bin = fs::canonical("/proc/self/exe").parent_path();
  const fs::path out = o.out.empty() ? fs::temp_directory_path() / ("kestrel-link-sweep-" + std::to_string(::getpid()))
                                     : fs::path(o.out);
  std::vector<std::string> rows, json_rows;
  bool all_well = true;
  for (const double loss : o.losses) {
    kestrel::link::SplitFlightOptions f;
    f.bin_dir = bin;
    f.out_dir = out / fmt::format("loss-{:g}", loss);
    f.loss_percent = loss;
    f.delay_ms = o.delay_ms;
    f.jitter_ms = o.jitter_ms;
    f.rate_mbit = o.rate_mbit;
    f.seed = o.seed;
    f.duration_s = o.duration_s;
    spdlog::info("flying at {:g} % loss ({})", loss, f.out_dir.string());
    const auto r = kestrel::link::fly_split(f);
    const bool well = r.problems.empty() && r.launch_exit == 0;
    all_well &= well;
    if (!r.problems.empty()) spdlog::warn("{:g} %: {}", loss, r.problems);
    rows.push_back(fmt::format(
        "| {:g} % | {:.1f} / {:.1f} cm | {} received, {} applied | {} of {} | {} (SLAM {}) | {} of {} ({} lost, {} queue full) | "
        "{:.1f} | {}; {} ({}), {} ({}) |",
        loss, r.deviation_mean_m * 100, r.deviation_max_m * 100, r.corrections_received, r.corrections_applied,
        r.plans_answered, r.plans_received, r.mapper_keyframes, r.slam_keyframes, r.datagrams_lost + r.datagrams_queue_full,
        r.datagrams_offered, r.datagrams_lost, r.datagrams_queue_full, r.up_mbit_s, r.launch_exit, r.goto_out_exit,
        r.goto_out_attempts, r.goto_back_exit, r.goto_back_attempts));
    json_rows.push_back(fmt::format(
        "{{\"loss_percent\": {:g}, \"deviation_mean_m\": {:.4f}, \"deviation_max_m\": {:.4f}, \"hover_samples\": {}, "
        "\"corrections_received\": {}, \"corrections_applied\": {}, \"plans_answered\": {}, \"plans_received\": {}, \"mapper_keyframes\": {}, "
        "\"slam_keyframes\": {}, \"datagrams_offered\": {}, \"datagrams_lost\": {}, \"datagrams_queue_full\": {}, "
        "\"up_mbit_s\": {:.2f}, \"launch_exit\": {}, \"goto_exits\": [{}, {}], \"vo_frames\": {}, \"vo_motions\": {}, "
        "\"state_max_gap_s\": {:.3f}}}",
        loss, r.deviation_mean_m, r.deviation_max_m, r.hover_samples, r.corrections_received, r.corrections_applied,
        r.plans_answered, r.plans_received, r.mapper_keyframes, r.slam_keyframes, r.datagrams_offered, r.datagrams_lost,
        r.datagrams_queue_full, r.up_mbit_s, r.launch_exit, r.goto_out_exit, r.goto_back_exit, r.vo_frames,
        r.vo_motions, r.state_max_gap_s));
  }
  fmt::print("link {:g} ± {:g} ms, {:g} Mbit/s, seed {}, {:g} s flights; flights in {}\n\n", o.delay_ms, o.jitter_ms,
             o.rate_mbit, o.seed, o.duration_s, out.string());
  fmt::print("| loss | true deviation holding (mean / max) | SLAM corrections onboard | plans with a path, of those received | mapper keyframes "
             "| datagrams dropped | up, Mbit/s | exits: launch; goto out (requests), back (requests) |\n"
             "|---|---|---|---|---|---|---|---|\n");
  for (const auto& row : rows) fmt::print("{}\n", row);
  if (!o.json.empty()) {
    std::string json = "[\n";
    for (size_t i = 0; i < json_rows.size(); ++i) json += "  " + json_rows[i] + (i + 1 < json_rows.size() ? ",\n" : "\n");
    json += "]\n";
    kestrel::write_file_atomically(o.json, json);
  }
  return all_well ? kestrel::kExitOk : kestrel::kExitFailure;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app(
      "link-sweep",
      "Flies the system split over the emulated link (onboard and offboard in two namespaces, "
      "kestrel launch --link) once per loss rate, and prints a Markdown table: true deviation "
      "while holding, corrections, plans, mapper keyframes, datagrams dropped. Needs what "
      "launch --link needs (root or user namespaces) and lcm-logger. Exit: 0 every flight ran; 1 one did not; 2 usage.");
  Options o;
  app.add_option("--losses", o.losses, "Loss rates to fly, %")->delimiter(',')->check(CLI::Range(0.0, 100.0))->capture_default_str();
  app.add_option("--out", o.out, "Folder for the flights (default: a new one in $TMPDIR)");
  app.add_option("--seed", o.seed, "Seed of the link and the simulator")->capture_default_str();
  app.add_option("--duration", o.duration_s, "Seconds of each flight")->check(CLI::Range(20.0, 600.0))->capture_default_str();
  app.add_option("--delay", o.delay_ms, "Link delay, ms")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--jitter", o.jitter_ms, "Link jitter, ms")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--rate", o.rate_mbit, "Link rate, Mbit/s")->check(kestrel::cli::Positive)->capture_default_str();
  app.add_option("--json", o.json, "Also write the results here (JSON)");
  return app.run(argc, argv, [&] { return sweep(o); });
}
