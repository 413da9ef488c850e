// kestrel-eval: scores an estimated trajectory against ground truth (ATE, RPE, the paper's
// velocity error and gross failures), from TUM files or LCM logs; optionally writes JSON, a
// plot, or the estimate as a TUM file. See tools/eval/README.md.

#include <spdlog/spdlog.h>

#include <cmath>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/error.h"
#include "common/image/image_io.h"
#include "common/transport/channels.h"
#include "metrics/alignment.h"
#include "metrics/evaluate.h"
#include "tools/eval/log_input.h"
#include "tools/eval/plot.h"
#include "tools/eval/report.h"
#include "tools/eval/trajectory_input.h"

namespace {

using namespace kestrel;
using namespace kestrel::eval;

constexpr const char* kAuto = "auto";

struct InputSpec {
  std::string path;
  std::string channel;  // "" = not given in the spec
};

// FILE[:CHANNEL]: a name that exists as a file is taken whole, so paths with ':' still work.
InputSpec split_spec(const std::string& spec) {
  std::error_code ec;
  const auto colon = spec.rfind(':');
  if (std::filesystem::exists(spec, ec) || colon == std::string::npos || colon == 0 ||
      colon + 1 == spec.size()) {
    return {spec, ""};
  }
  return {spec.substr(0, colon), spec.substr(colon + 1)};
}

TrajectoryInput read_input(const std::string& option, const std::string& spec_text,
                           const std::string& channel_option,
                           const std::vector<std::string>& auto_channels) {
  const InputSpec spec = split_spec(spec_text);
  TrajectoryInput in;
  if (is_lcm_log(spec.path)) {
    const std::string channel = spec.channel.empty() ? channel_option : spec.channel;
    in = read_log_input(spec.path,
                        channel == kAuto ? auto_channels : std::vector<std::string>{channel});
    if (!in.diagnostics.damage.empty()) spdlog::warn("{}", in.diagnostics.damage);
    for (const std::string& p : in.diagnostics.problems())
      if (p != in.diagnostics.damage) spdlog::warn("{}: {}", in.source, p);
  } else {
    if (!spec.channel.empty()) {
      throw CLI::ValidationError(option, "channel '" + spec.channel + "' given, but " + spec.path +
                                             " is a text file, not an LCM log");
    }
    in = read_tum_input(spec.path);
  }
  if (in.frame_utimes.empty()) throw InputError(in.source + ": no poses");
  return in;
}

int64_t to_utime(double seconds) { return std::llround(seconds * 1e6); }

}  // namespace

int main(int argc, char** argv) {
  cli::App app("eval",
               "Scores an estimated trajectory against ground truth: ATE, RPE, velocity error and "
               "gross failures.\nInputs are TUM trajectory files or LCM logs (told apart by "
               "content), given as FILE[:CHANNEL].");
  app.option_defaults()->always_capture_default();
  std::string gt_spec, est_spec, frames_path, plot_path, tum_path;
  std::string gt_channel = channel::kGroundTruth;
  std::string est_channel = kAuto;
  bool json = false, no_align = false, no_gap_failures = false;
  std::vector<std::string> world_from;  // GT EST of the session that made a saved map
  double gt_max_gap_s = 0.02, est_max_gap_s = 0.0, rpe_delta_s = 1.0, rpe_tolerance_s = 0.1,
         gross_velocity_mps = 1.0;

  app.add_option("--gt", gt_spec, "Ground truth, FILE[:CHANNEL] (TUM file or LCM log)");
  app.add_option("--est", est_spec, "Estimate, FILE[:CHANNEL] (TUM file or LCM log)")->required();
  app.add_option("--gt-channel", gt_channel, "Ground-truth channel of a log (ground_truth_t)");
  app.add_option("--est-channel", est_channel,
                 "Estimate channel of a log (state_t, vo_update_t, slam_graph_t or ground_truth_t); auto = "
                 "STATE if the log has it, else VO_UPDATE");
  app.add_option("--frames", frames_path,
                 "Reference frame list (TUM list such as rgb.txt; default: the estimate's "
                 "frames); frames without an estimate are gross failures");
  app.add_flag("--json", json, "Print the report as JSON instead of a table");
  app.add_option("--plot", plot_path, "Write a PNG with the top view and the errors over time");
  app.add_option("--to-tum", tum_path,
                 "Write the estimated trajectory (as read, e.g. VO chained) as a TUM file; "
                 "without --gt, do only that");
  app.add_flag("--no-align", no_align, "Compute the ATE without the rigid alignment");
  app.add_option("--world-from", world_from,
                 "GT EST of another run in the same world (the flight that made a saved map): its whole poses "
                 "aligned to its truth once put this estimate in the truth's world, which is then scored with no "
                 "alignment of its own (a flight relocalised in that map)")
      ->expected(2);
  app.add_option("--gt-max-gap", gt_max_gap_s,
                 "Interpolate ground truth only between samples within this of the frame (s)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--est-max-gap", est_max_gap_s,
                 "The same for the estimate; 0 = exact time stamps (raise for STATE) (s)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--rpe-delta", rpe_delta_s, "RPE time step (s)")->check(cli::Positive);
  app.add_option("--rpe-tolerance", rpe_tolerance_s,
                 "Largest difference between an RPE pair's span and the step (s)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--gross-velocity", gross_velocity_mps,
                 "Velocity error above which a frame is a gross failure (m/s)")
      ->check(cli::Positive);
  app.add_flag("--no-gap-failures", no_gap_failures,
               "Do not count the first frame after a ground-truth gap as a gross failure");

  return app.run(argc, argv, [&]() -> int {
    if (gt_spec.empty() && tum_path.empty())
      throw CLI::RequiredError("--gt (required unless only --to-tum is asked)");
    TrajectoryInput est =
        read_input("--est", est_spec, est_channel, {channel::kState, channel::kVoUpdate});
    if (!tum_path.empty()) {
      write_tum_trajectory(tum_path, est.trajectory);
      spdlog::info("wrote {} poses of {} to {}", est.trajectory.size(), est.source, tum_path);
      if (gt_spec.empty()) return kExitOk;
    }
    TrajectoryInput gt = read_input("--gt", gt_spec, gt_channel, {channel::kGroundTruth});
    const std::string compared = reconcile_frames(gt, est);
    if (!world_from.empty()) {
      TrajectoryInput gt0 = read_input("--world-from", world_from[0], gt_channel, {channel::kGroundTruth});
      TrajectoryInput est0 = read_input("--world-from", world_from[1], est_channel, {channel::kState, channel::kVoUpdate});
      reconcile_frames(gt0, est0);
      metrics::Alignment world;
      try {
        world = metrics::align_poses(est0.trajectory, gt0.trajectory, to_utime(gt_max_gap_s));
      } catch (const std::invalid_argument&) {
        throw InputError(world_from[0] + " covers no pose of " + world_from[1] + ": no world to take");
      }
      std::vector<StampedPose> moved;
      for (const StampedPose& p : est.trajectory.poses()) moved.push_back({p.utime, world.T_gt_est * p.T});
      est.trajectory = Trajectory(std::move(moved));
      no_align = true;
      spdlog::info("the estimate put in the truth's world by {} against {} (whole poses), not aligned itself",
                   world_from[1], world_from[0]);
    }

    metrics::EvalOptions options;
    options.gt_max_gap_us = to_utime(gt_max_gap_s);
    options.est_max_gap_us = to_utime(est_max_gap_s);
    options.align = !no_align;
    options.rpe_delta_s = rpe_delta_s;
    options.rpe_tolerance_s = rpe_tolerance_s;
    options.gross_velocity_mps = gross_velocity_mps;
    options.gross_after_gt_gap = !no_gap_failures;
    const std::vector<int64_t> frames =
        frames_path.empty() ? est.frame_utimes : read_frame_list(frames_path);
    const metrics::Evaluation evaluation = metrics::evaluate(frames, est.trajectory, gt.trajectory, options);

    const ReportInputs inputs{gt, est, frames_path.empty() ? "the estimate" : frames_path,
                              compared};
    if (json) {
      std::cout << json_report(inputs, evaluation, options).dump(2) << "\n";
    } else {
      std::cout << text_report(inputs, evaluation, options);
    }
    if (!plot_path.empty()) {
      // File names only: a plot is looked at elsewhere, and a folder says nothing there.
      const auto shown = [](const std::string& source) { return std::filesystem::path(source).filename().string(); };
      image::write_png(plot_path, render_plot(evaluation, options, shown(est.source) + "  vs  " + shown(gt.source)));
      spdlog::info("wrote {}", plot_path);
    }
    return kExitOk;
  });
}
