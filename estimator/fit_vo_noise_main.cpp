// kestrel-fit-vo-noise: fits the paper's constant VO noise model from a log holding
// VO_UPDATE and GROUND_TRUTH (or a separate TUM ground truth), and prints it in the form the
// estimator takes (--vo-noise constant --vo-sigma ...). See README.md.

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <cstdio>
#include <iostream>

#include "common/cli.h"
#include "common/error.h"
#include "estimator/log_run.h"
#include "estimator/vo_noise_fit.h"

namespace {

using namespace kestrel;
using namespace kestrel::estimator;

struct Options {
  std::string log;
  std::string ground_truth;
  double max_gap_s = 0.05;
  LogChannels channels;
};

std::string row(const Eigen::Matrix<double, 6, 1>& v, const char* separator) {
  std::string s;
  char buffer[32];
  for (int i = 0; i < 6; ++i) {
    std::snprintf(buffer, sizeof buffer, "%s%.6g", i ? separator : "", v[i]);
    s += buffer;
  }
  return s;
}

// The keyframe share, by lag and against its control; "n/a" where nothing measured it.
std::string keyframe_share(const VoNoiseFit& fit) {
  if (fit.keyframes_with_pairs == 0)
    return "keyframe share of the error: n/a (no keyframe with two usable updates)\n";
  std::string s = fmt::format("keyframe share of the error: {:.3f} (over {} keyframes with two updates or more)\n",
                              fit.keyframe_share, fit.keyframes_with_pairs);
  s += "  by lag (usable updates apart):";
  for (size_t b = 0; b < fit.share_by_lag.size(); ++b) {
    if (fit.share_by_lag[b].pairs == 0) continue;
    const size_t low = size_t{1} << b, high = (size_t{2} << b) - 1;
    const std::string lags = b + 1 == fit.share_by_lag.size() ? fmt::format("{}+", low)
                             : low == high                    ? fmt::format("{}", low)
                                                              : fmt::format("{}-{}", low, high);
    s += fmt::format(" {} {:.2f}", lags, fit.share_by_lag[b].share);
  }
  s += "\n";
  if (fit.rekey_pairs > 0)
    s += fmt::format("  consecutive updates across a re-key (negative: the frame's error changes sides): {:.3f} ({} pairs)\n",
                     fit.share_across_rekey, fit.rekey_pairs);
  return s;
}

int run(const Options& o) {
  VoAndTruth input = read_vo_and_truth(o.log, o.channels);
  if (!input.skips.damage.empty()) spdlog::warn("{}", input.skips.damage);
  if (input.skips.rejected > 0)
    spdlog::warn("{} messages skipped; the first: {}", input.skips.rejected, input.skips.first_reason);
  // A separate file is T_world_body, like the GROUND_TRUTH body frame.
  if (!o.ground_truth.empty()) input.truth = read_tum_trajectory(o.ground_truth);
  if (input.truth.empty())
    throw InputError(o.log + ": no ground truth on " + o.channels.ground_truth +
                     " (give one with --ground-truth)");
  const VoNoiseFit fit =
      fit_vo_noise(input.updates, input.truth, static_cast<int64_t>(o.max_gap_s * 1e6));
  std::cout << "updates used: " << fit.used << " (" << fit.failed << " failed, " << fit.uncovered
            << " without ground truth)\n"
            << "mean keyframe-to-frame interval: " << fit.mean_interval_s << " s\n"
            << "error mean  [dx dy dz m, rx ry rz rad]: " << row(fit.mean, " ") << "\n"
            << "error sigma [dx dy dz m, rx ry rz rad]: " << row(fit.sigma, " ") << "\n"
            << "reported covariance: mean e^T C^-1 e / 6 = " << fit.reported_nees << "\n"
            << keyframe_share(fit)
            << "estimator options: --vo-noise constant --vo-sigma " << row(fit.sigma, ",") << "\n";
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app("fit-vo-noise",
                        "Fit the constant VO noise model (sigmas of [dp; dtheta]) against ground truth");
  Options o;
  app.add_option("--log", o.log, "LCM log with VO_UPDATE (and GROUND_TRUTH)")
      ->required()->check(CLI::ExistingFile);
  app.add_option("--ground-truth", o.ground_truth, "TUM file of T_world_body instead of GROUND_TRUTH")
      ->check(CLI::ExistingFile);
  app.add_option("--max-gap", o.max_gap_s, "Largest ground-truth gap to interpolate across, s")
      ->check(cli::Positive)->capture_default_str();
  app.add_option("--vo-channel", o.channels.vo, "VO channel")->capture_default_str();
  app.add_option("--ground-truth-channel", o.channels.ground_truth, "Ground-truth channel")
      ->capture_default_str();
  return app.run(argc, argv, [&] { return run(o); });
}
