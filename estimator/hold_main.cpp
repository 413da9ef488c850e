// kestrel-hold: scores a position hold flown in the synthetic world (the paper's Fig. 14)
// from an LCM log holding GROUND_TRUTH and the STATE the vehicle flew on (README.md, "Position
// hold"). The hold target is the first truth pose: the sim's vehicle starts at rest there and
// holds it. --print-start gives that pose as the estimator's start options.

#include <algorithm>
#include <cmath>
#include <iostream>
#include <set>
#include <vector>

#include "common/cli.h"
#include "common/error.h"
#include "common/numbers.h"
#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "estimator/eval/hold_score.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vo_update_t.hpp"

namespace {

using namespace kestrel;
using namespace kestrel::estimator;

struct Options {
  std::string log;
  double from_s = -1.0;
  bool print_start = false;
  bool truth_only = false;
};

TimedPosition timed(int64_t utime, const kestrel::pose3_t& pose, const char* what) {
  const Eigen::Isometry3d T = transport::from_message(pose, what);
  return {utime, T.translation(), std::atan2(T.linear()(1, 0), T.linear()(0, 0))};
}

std::vector<TimedPosition> read_truth(const std::string& log) {
  std::vector<TimedPosition> out;
  for (const auto& m : transport::read_messages<kestrel::ground_truth_t>(log, channel::kGroundTruth)) {
    if (m.frame != kestrel::ground_truth_t::FRAME_BODY)
      throw InputError(log + ": GROUND_TRUTH is not of the body frame (a TUM sequence?); a hold needs the sim's");
    out.push_back(timed(m.utime, m.T_world_frame, channel::kGroundTruth));
  }
  if (out.empty()) throw InputError(log + ": no GROUND_TRUTH messages");
  return out;
}

std::string cm(const Spread& s) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "mean %5.1f cm, max %5.1f cm", 100.0 * s.mean, 100.0 * s.max);
  return buf;
}

int run(const Options& o) {
  const std::vector<TimedPosition> truth = read_truth(o.log);
  const TimedPosition& start = truth.front();
  if (o.print_start) {
    std::printf("--init-position %.6f,%.6f,%.6f --init-yaw %.6f\n", start.p.x(), start.p.y(),
                start.p.z(), start.yaw);
    return kExitOk;
  }
  // The vehicle flies on STATE once its status is OK or DEGRADED (the sim's vehicle_estimate);
  // before that, on the truth.
  std::vector<TimedPosition> flown;
  int64_t states = 0, degraded = 0;
  for (const auto& m : transport::read_messages<kestrel::state_t>(o.log, channel::kState)) {
    ++states;
    if (m.status != kestrel::state_t::STATUS_OK && m.status != kestrel::state_t::STATUS_DEGRADED) continue;
    if (m.status == kestrel::state_t::STATUS_DEGRADED) ++degraded;
    flown.push_back(timed(m.utime, m.T_world_body, channel::kState));
  }
  if (flown.empty() && !o.truth_only)
    throw InputError(o.log + ": no usable STATE (OK or DEGRADED): the vehicle never flew on the estimator");
  if (o.truth_only) flown.clear();
  const double on_state_s = flown.empty() ? 0.0 : 1e-6 * static_cast<double>(flown.front().utime - start.utime);
  const double from_s = o.from_s >= 0 ? o.from_s : std::max(0.0, on_state_s);
  // The VO's keyframe policy decides how its errors add up over a hold: count the references
  // its motions were measured from, and their inliers.
  int64_t vo = 0, vo_ok = 0;
  std::set<int64_t> references;
  std::vector<int> inliers;
  for (const auto& m : transport::read_messages<kestrel::vo_update_t>(o.log, channel::kVoUpdate)) {
    ++vo;
    if (m.status != kestrel::vo_update_t::STATUS_OK) continue;
    ++vo_ok;
    references.insert(m.reference_utime);
    inliers.push_back(m.num_reprojection_inliers);
  }
  std::sort(inliers.begin(), inliers.end());
  const int median_inliers = inliers.empty() ? 0 : inliers[inliers.size() / 2];
  HoldScore s;
  try {
    s = score_hold(truth, flown, start.p, from_s);
  } catch (const std::invalid_argument& e) {
    throw InputError(o.log + ": " + e.what());
  }
  std::printf("target: %.3f %.3f %.3f (the first GROUND_TRUTH), yaw %.3f rad\n", start.p.x(),
              start.p.y(), start.p.z(), start.yaw);
  if (o.truth_only) {
    std::printf("truth only; scored %.2f to %.2f s (%.1f s)\n", s.scored_from_s, s.scored_to_s,
                s.scored_to_s - s.scored_from_s);
  } else {
    std::printf("flying on STATE from %.2f s; scored %.2f to %.2f s (%.1f s)\n", on_state_s,
                s.scored_from_s, s.scored_to_s, s.scored_to_s - s.scored_from_s);
    std::printf("STATE: %lld messages, %lld usable, %lld of them DEGRADED; VO_UPDATE: %lld (%lld OK)\n",
                static_cast<long long>(states), static_cast<long long>(flown.size()),
                static_cast<long long>(degraded), static_cast<long long>(vo), static_cast<long long>(vo_ok));
    std::printf("VO: motions from %zu reference frames, median %d inliers\n", references.size(), median_inliers);
  }
  std::cout << "hold, truth from target, horizontal: " << cm(s.truth_horizontal) << "\n"
            << "hold, truth from target, 3D:         " << cm(s.truth_3d) << "\n";
  if (!o.truth_only) {
    std::cout << "estimator, truth vs STATE, horizontal: " << cm(s.error_horizontal) << "\n"
              << "estimator, truth vs STATE, 3D:         " << cm(s.error_3d) << "\n";
    std::printf("estimator, yaw error: mean %.2f deg, max %.2f deg\n", s.error_yaw.mean * 180 / kPi,
                s.error_yaw.max * 180 / kPi);
  }
  if (s.unmatched_estimates > 0)
    std::printf("STATE without a GROUND_TRUTH within 3 ms: %lld (left out)\n",
                static_cast<long long>(s.unmatched_estimates));
  std::cout << "paper (Fig. 14, real flight, 90 s): mean 6.2 cm, max 19 cm\n";
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::cli::App app("hold", "Score a position hold in the synthetic world: truth vs target, truth vs STATE, from an LCM log");
  Options o;
  app.add_option("--log", o.log, "LCM log with GROUND_TRUTH and STATE (VO_UPDATE counted if there)")
      ->required()->check(CLI::ExistingFile);
  app.add_option("--from", o.from_s,
                 "Score from this many seconds after the first GROUND_TRUTH (default: from the "
                 "first usable STATE, when the vehicle starts flying on the estimator)")
      ->check(CLI::Range(0.0, 1e6));
  app.add_flag("--truth-only", o.truth_only,
               "Score the truth against the target only, ignoring STATE: a flight on the truth "
               "(kestrel-sim --flight vehicle --log ..., or --vehicle-feedback truth), the baseline "
               "that the wind and the controller alone give (use --from 0.5 to compare)");
  app.add_flag("--print-start", o.print_start,
               "Print the first GROUND_TRUTH pose as --init-position/--init-yaw and exit");
  return app.run(argc, argv, [&] { return run(o); });
}
