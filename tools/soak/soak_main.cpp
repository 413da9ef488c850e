// kestrel-soak: the whole system flown for a long time (30 simulated minutes by default) along
// a repeating route, every process's memory and CPU time per frame sampled while it flies, and
// per process the verdict: flat after the warm-up, or growing. The flight is kestrel fly-plans'
// (tools/flights/closed_loop.h: the sim's closed-loop vehicle, vo, estimator, follow, slam and
// mapper in lock-step in a private network); the route is the world's `loop` flight, lap after
// lap (soak_route.h); the figures are soak.h's, the picture soak_plot.h's. See README.md.

#include <fmt/format.h>
#include <lcm/lcm-cpp.hpp>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>

#include "common/atomic_file.h"
#include "common/cli.h"
#include "common/error.h"
#include "common/image/image_io.h"
#include "common/interrupt.h"
#include "common/transport/channels.h"
#include "common/transport/lcm_url.h"
#include "common/transport/message.h"
#include "drivers/sim/simulation.h"
#include "drivers/sim/world_catalog.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/slam_graph_t.hpp"
#include "kestrel/vo_update_t.hpp"
#include "tools/flights/closed_loop.h"
#include "tools/launch/supervisor.h"
#include "tools/soak/proc_memory.h"
#include "tools/soak/soak.h"
#include "tools/soak/soak_plot.h"
#include "tools/soak/soak_route.h"

namespace {

using namespace kestrel;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

struct Options {
  double minutes = 30.0;
  double sample_period_s = 10.0;
  std::string world = "room";
  std::string map;
  uint64_t seed = 1;
  double speed = 0.5;
  double warmup_minutes = 5.0;
  double flat_mb_per_10min = 2.0;
  bool require_flat = false;
  double ack_timeout = 60.0;
  std::string out = "soak-output";
  std::string lcm_url;
};

// What the soak hears of the flight on LCM, besides the processes' own figures: the simulated
// time and the distance flown (GROUND_TRUTH), the frames the VO measured and its own time per
// frame (VO_UPDATE), SLAM's keyframes (SLAM_GRAPH) and corrections (SLAM_CORRECTION).
// LCM 1.3 takes member functions, not lambdas.
class FlightListener {
 public:
  explicit FlightListener(const std::string& url) : lcm_(url) {
    if (!lcm_.good()) throw UnavailableError("cannot open LCM at " + url);
    for (lcm::Subscription* s :
         {lcm_.subscribe(channel::kGroundTruth, &FlightListener::truth, this),
          lcm_.subscribe(channel::kVoUpdate, &FlightListener::vo, this),
          lcm_.subscribe(channel::kSlamGraph, &FlightListener::graph, this),
          lcm_.subscribe(channel::kSlamCorrection, &FlightListener::correction, this)})
      s->setQueueCapacity(2000);  // ten seconds of GROUND_TRUTH between two drains, at worst
  }

  /// Handles every message waiting; never blocks.
  void drain() {
    while (lcm_.handleTimeout(0) > 0) {
    }
  }

  double sim_s() const { return sim_s_; }
  double distance_m() const { return distance_m_; }
  int64_t frames() const { return first_seq_ < 0 ? 0 : last_seq_ - first_seq_ + 1; }
  int64_t vo_failures() const { return vo_failures_; }
  int64_t keyframes() const { return keyframes_; }
  int64_t corrections() const { return corrections_; }
  /// The VO's own mean time per frame since the last call (NaN without frames).
  double take_vo_elapsed_ms() {
    const double mean = vo_count_ > 0 ? vo_elapsed_sum_ / static_cast<double>(vo_count_) : soak::kNaN;
    vo_elapsed_sum_ = 0.0;
    vo_count_ = 0;
    return mean;
  }

 private:
  void truth(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    const auto gt = decoded<ground_truth_t>(rbuf, channel);
    if (!gt) return;
    const Eigen::Vector3d p(gt->T_world_frame.position[0], gt->T_world_frame.position[1], gt->T_world_frame.position[2]);
    if (have_position_) distance_m_ += (p - position_).norm();
    position_ = p;
    have_position_ = true;
    sim_s_ = std::max(sim_s_, 1e-6 * static_cast<double>(gt->utime - sim::SimulationOptions{}.start_utime));
  }
  void vo(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    const auto u = decoded<vo_update_t>(rbuf, channel);
    if (!u) return;
    if (first_seq_ < 0) first_seq_ = u->seq;
    last_seq_ = std::max(last_seq_, u->seq);
    if (u->status != vo_update_t::STATUS_OK) ++vo_failures_;
    if (std::isfinite(u->elapsed_ms)) {
      vo_elapsed_sum_ += static_cast<double>(u->elapsed_ms);
      ++vo_count_;
    }
  }
  void graph(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    if (const auto g = decoded<slam_graph_t>(rbuf, channel)) keyframes_ = g->num_keyframes;
  }
  void correction(const lcm::ReceiveBuffer*, const std::string&) { ++corrections_; }

  template <class Msg>
  std::optional<Msg> decoded(const lcm::ReceiveBuffer* rbuf, const std::string& channel) {
    try {
      return transport::decode_message<Msg>(rbuf->data, rbuf->data_size, channel);
    } catch (const InputError& e) {
      spdlog::warn("{}", e.what());
      return std::nullopt;
    }
  }

  lcm::LCM lcm_;
  double sim_s_ = 0.0;
  Eigen::Vector3d position_ = Eigen::Vector3d::Zero();
  bool have_position_ = false;
  double distance_m_ = 0.0;
  int64_t first_seq_ = -1, last_seq_ = -1, vo_failures_ = 0;
  double vo_elapsed_sum_ = 0.0;
  int64_t vo_count_ = 0;
  int64_t keyframes_ = 0, corrections_ = 0;
};

// Takes a round of samples every period while the flight runs (FlightWatch), and notes each
// process that ended before the flight did.
class Sampler {
 public:
  Sampler(FlightListener& listener, double period_s, fs::path out)
      : listener_(listener), period_(std::chrono::duration<double>(period_s)), out_(std::move(out)) {}

  void operator()(const launch::Supervisor& processes, bool ending) {
    listener_.drain();
    note_ended(processes, ending);
    const Clock::time_point now = Clock::now();
    if (!ending && now < next_) return;
    next_ = now + std::chrono::duration_cast<Clock::duration>(period_);
    round(processes, now);
    // What is there so far survives a soak that is killed or dies with the machine.
    if (progress_.size() % 10 == 0 || ending) save_csv();
    if (now >= next_log_) {
      next_log_ = now + std::chrono::minutes(1);
      std::string line;
      for (auto it = samples_.end() - static_cast<std::ptrdiff_t>(std::min(samples_.size(), last_round_size_));
           it != samples_.end(); ++it)
        line += fmt::format(" {} {:.0f} MB", it->process, it->rss_mb);
      spdlog::info("{:.1f} min simulated, {} frames:{}", listener_.sim_s() / 60.0, listener_.frames(), line);
    }
  }

  void save_csv() const {
    write_file_atomically((out_ / "samples.csv").string(), soak::samples_csv(samples_));
    write_file_atomically((out_ / "progress.csv").string(), soak::progress_csv(progress_));
  }

  const std::vector<soak::ProcessSample>& samples() const { return samples_; }
  const std::vector<soak::ProgressSample>& progress() const { return progress_; }
  const std::vector<std::pair<std::string, std::string>>& died() const { return died_; }

 private:
  void round(const launch::Supervisor& processes, Clock::time_point now) {
    if (!started_) started_ = now;
    const double wall_s = std::chrono::duration<double>(now - *started_).count();
    const double sim_s = listener_.sim_s();
    const int64_t frames = listener_.frames();
    last_round_size_ = 0;
    for (const launch::Supervisor::Child& c : processes.children()) {
      if (c.pid <= 0) continue;
      const auto memory = soak::process_memory(c.pid);
      const auto cpu = launch::process_cpu_seconds(c.pid);
      if (!memory || !cpu) continue;  // it ended just now: the supervisor will say so
      samples_.push_back({wall_s, sim_s, c.spec.name, static_cast<int>(c.pid), memory->rss_mb, memory->anon_mb, *cpu, frames});
      ++last_round_size_;
    }
    progress_.push_back({wall_s, sim_s, frames, listener_.vo_failures(), listener_.take_vo_elapsed_ms(), listener_.distance_m(),
                         listener_.keyframes(), listener_.corrections()});
  }

  void note_ended(const launch::Supervisor& processes, bool ending) {
    for (const launch::Supervisor::Child& c : processes.children()) {
      if (c.pid > 0 || !c.last_ending) continue;
      if (ending && c.spec.name == "sim" && c.last_ending->code == 0) continue;  // the flight's end
      const bool known = std::any_of(died_.begin(), died_.end(), [&](const auto& d) { return d.first == c.spec.name; });
      if (!known) died_.push_back({c.spec.name, c.last_ending->description});
    }
  }

  FlightListener& listener_;
  std::chrono::duration<double> period_;
  fs::path out_;
  Clock::time_point next_{}, next_log_{};
  std::optional<Clock::time_point> started_;
  size_t last_round_size_ = 0;
  std::vector<soak::ProcessSample> samples_;
  std::vector<soak::ProgressSample> progress_;
  std::vector<std::pair<std::string, std::string>> died_;
};

int run(const Options& o) {
  // The route first: a world that does not load is said before anything is set up.
  const soak::Route route = [&] {
    const sim::World world = sim::load_world(o.world, o.map);  // a bad file: InputError, exit 3
    try {
      return soak::loop_route(world);
    } catch (const std::runtime_error& e) {  // no loop fits the world
      throw CLI::ValidationError("--world", e.what());
    }
  }();
  const double run_s = 60.0 * o.minutes;
  soak::Criteria criteria;
  criteria.run_s = run_s;
  criteria.warmup_s = std::min(60.0 * o.warmup_minutes, run_s / 3.0);
  criteria.flat_mb_per_10min = o.flat_mb_per_10min;

  // Before any thread: the flight's processes and this listener share this private network.
  flights::enter_flight_network("soak");
  const auto& interrupted = catch_interrupts();
  const std::string url = transport::resolve_lcm_url(o.lcm_url);
  const fs::path tool_dir = fs::canonical("/proc/self/exe").parent_path();
  const fs::path out = flights::make_output_folder(o.out);
  std::error_code ec;
  for (const char* stale : {"report.md", "soak.json", "soak.png", "samples.csv", "progress.csv"})
    fs::remove(out / stale, ec);  // an earlier soak's results must not pass for this one's

  flights::FlightSetup setup;
  setup.world = o.world;
  setup.map = o.map;
  setup.start = route.start;
  // Laps enough for the whole flight at cruise speed and one more: the follower never reaches
  // the end of its path, where it would stop.
  setup.waypoints = soak::laps(route, run_s * o.speed + route.lap_length_m);
  setup.seed = o.seed;
  setup.duration_s = run_s;
  setup.speed_m_s = o.speed;
  setup.ack_timeout_s = o.ack_timeout;
  setup.dir = out / "flight";
  setup.record = false;
  const size_t lap_count = (setup.waypoints.size() - 1) / route.lap.size();
  const std::string heading = fmt::format(
      "World `{}`, its `loop` flight as a route of {:.1f} m per lap ({} waypoints; {} laps given to the follower), "
      "flown at {} m/s by the simulator's closed-loop vehicle with vo, estimator, follow, slam and mapper in lock-step, "
      "seed {}; each process sampled every {} s of wall time.",
      o.world, route.lap_length_m, route.lap.size(), lap_count, o.speed, o.seed, o.sample_period_s);
  spdlog::info("soak: {:.1f} simulated minutes in {}: a {:.1f} m lap, {} laps at most; writing {}", o.minutes, o.world,
               route.lap_length_m, lap_count, out.string());

  FlightListener listener(url);
  Sampler sampler(listener, o.sample_period_s, out);
  // A process that dies ends the soak: what follows would not be the system's memory.
  const flights::FlightRun flown = flights::fly(
      setup, tool_dir, url, [&] { return interrupted.load() || !sampler.died().empty(); },
      [&](const launch::Supervisor& processes, bool ending) { sampler(processes, ending); });
  sampler.save_csv();

  std::string failure = flown.ok ? "" : flown.failure;
  if (interrupted) {  // which signal, and when: a soak stopped by someone else says so
    const int sig = interrupt_signal();
    failure = fmt::format("interrupted by signal {} ({}) at {:.1f} simulated minutes", sig,
                          sig > 0 ? strsignal(sig) : "?", listener.sim_s() / 60.0);
  } else if (!sampler.died().empty()) {
    failure.clear();
    for (const auto& [name, how] : sampler.died())
      failure += fmt::format("{}{} {} during the flight:\n{}", failure.empty() ? "" : "\n", name, how,
                             launch::log_tail(setup.dir / (name + ".log"), 5));
  }
  const soak::Summary summary = soak::summarise(sampler.samples(), sampler.progress(), criteria, sampler.died());
  if (!summary.usable()) {
    if (interrupted) return kExitInterrupted;
    spdlog::error("nothing usable: {} samples over {:.1f} s of simulated flight{}", sampler.samples().size(),
                  summary.sim_s, failure.empty() ? "" : "; " + failure);
    return kExitFailure;
  }
  const std::string report = soak::markdown(summary, heading, failure);
  write_file_atomically((out / "report.md").string(), report);
  write_file_atomically((out / "soak.json").string(), soak::to_json(summary, failure).dump(2) + "\n");
  image::write_png((out / "soak.png").string(),
                   soak::render_plot(sampler.samples(), sampler.progress(), summary,
                                     fmt::format("kestrel soak: {} loop, {:.1f} of {:.1f} simulated minutes, seed {}",
                                                 o.world, summary.sim_s / 60.0, o.minutes, o.seed)));
  std::cout << report;
  if (interrupted) return kExitInterrupted;
  if (!failure.empty()) {
    spdlog::error("{}", failure);
    return kExitFailure;
  }
  if (o.require_flat && !summary.all_flat()) {
    spdlog::error("not every process is flat (--require-flat): see {}", (out / "report.md").string());
    return kExitFailure;
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  cli::App app("soak",
               "The whole system flown for a long time along a repeating route (the sim's closed-loop vehicle, vo, "
               "estimator, follow, slam, mapper in lock-step): every process's memory and CPU time per frame "
               "sampled, and whether each stays flat after the warm-up");
  Options o;
  app.add_option("--minutes", o.minutes, "Simulated minutes to fly")->check(cli::Positive)->capture_default_str();
  app.add_option("--sample-period", o.sample_period_s, "Sample every process this often (wall seconds)")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_option("--world", o.world, "The sim world whose loop flight is the route (kestrel sim --list)")
      ->check(CLI::Validator([](std::string& w) { return sim::unknown_world_error(w); }, ""))
      ->capture_default_str();
  app.add_option("--map", o.map, "The ROS map the stata world is built from");
  app.add_option("--seed", o.seed, "The simulator's seed (sensor noise and wind)")->capture_default_str();
  app.add_option("--speed", o.speed, "The follower's cruise speed (m/s)")->check(cli::Positive)->capture_default_str();
  app.add_option("--warmup", o.warmup_minutes,
                 "Simulated minutes of warm-up: the memory after it is the first sample from here (at most a third "
                 "of the run)")
      ->check(CLI::NonNegativeNumber)
      ->capture_default_str();
  app.add_option("--flat-bound", o.flat_mb_per_10min,
                 "Flat: the resident memory grows by less than this many MB per 10 simulated minutes over the last "
                 "two thirds of the run")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_flag("--require-flat", o.require_flat, "Exit 1 unless every process is flat");
  app.add_option("--ack-timeout", o.ack_timeout, "Lock-step: the longest wait for a process (s)")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_option("--out", o.out, "Folder for samples.csv, progress.csv, soak.png, report.md, soak.json and the logs")
      ->capture_default_str();
  app.add_option("--lcm-url", o.lcm_url, "LCM URL inside the private network (default: $LCM_DEFAULT_URL or kestrel's)");
  return app.run(argc, argv, [&] {
    if (const std::string e = sim::world_choice_error(o.world, o.map); !e.empty()) throw CLI::ValidationError("--world", e);
    return run(o);
  });
}
