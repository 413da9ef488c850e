#include "vo/sequence_run.h"

#include <algorithm>
#include <ctime>
#include <cmath>
#include <nlohmann/json.hpp>

#include "common/error.h"
#include "common/time.h"
#include "drivers/tum/tum_sequence.h"
#include "sensors/builtin_profiles.h"
#include "metrics/evaluate.h"
#include "vo/pose_chain.h"

namespace kestrel::vo {
namespace {

// 95 % quantile of chi-square with 6 degrees of freedom.
constexpr double kChi2_6_95 = 12.592;

static_assert(size_t(VoStatus::kBadInput) + 1 == kVoStatusCount, "a counter per status");

// CPU time of this thread: on a machine shared with other jobs it still measures the work of
// one core, where wall time would measure the contention.
double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * double(ts.tv_sec) + 1e-6 * double(ts.tv_nsec);
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double pos = q * double(v.size() - 1);
  const size_t i = static_cast<size_t>(pos);
  const double a = pos - double(i);
  return i + 1 < v.size() ? (1 - a) * v[i] + a * v[i + 1] : v[i];
}

// [dp; dtheta] taking the estimate to the truth, in the convention of every kestrel covariance.
Vector6d pose_error(const Eigen::Isometry3d& T_est, const Eigen::Isometry3d& T_true) {
  Vector6d e;
  e.head<3>() = T_true.translation() - T_est.translation();
  const Eigen::AngleAxisd aa(Eigen::Matrix3d(T_est.linear().transpose() * T_true.linear()));
  e.tail<3>() = aa.angle() * aa.axis();
  return e;
}

// The frames by status: RunFigures' frames, ok and by_status, the rest left unmeasured.
RunFigures count_by_status(const std::vector<VoResult>& results) {
  RunFigures f;
  f.frames = results.size();
  for (const VoResult& r : results) {
    f.ok += r.status == VoStatus::kOk;
    ++f.by_status.at(size_t(r.status));
  }
  return f;
}

}  // namespace

LoadedSequence load_tum_sequence(const std::string& folder) {
  const tum::TumSequence sequence(folder);
  LoadedSequence out;
  out.folder = folder;
  out.rgb_images = sequence.association().rgb_images;
  out.max_time_difference_us = tum::SequenceOptions{}.max_time_difference_us;
  out.frames.reserve(sequence.size());
  for (size_t i = 0; i < sequence.size(); ++i) out.frames.push_back(sequence.frame(i));
  if (sequence.has_ground_truth()) out.ground_truth = sequence.ground_truth();
  return out;
}

const sensors::SensorProfile& tum_sensor(const std::string& folder) {
  return sensors::profile_of_sensor(tum::sensor_model_of_folder(folder));
}

VoOptions with_tum_sensor(const std::string& folder, VoOptions options) {
  return with_sensor(tum_sensor(folder), std::move(options));
}

SequenceRun run_sequence(const std::vector<RgbdFrame>& frames, const VoOptions& options) {
  SequenceRun run;
  VisualOdometry vo(options);
  PoseChain chain;
  run.results.reserve(frames.size());
  for (const RgbdFrame& frame : frames) {
    const double t0 = thread_cpu_ms();
    VoResult r = vo.process(frame);
    run.process_ms.push_back(thread_cpu_ms() - t0);
    run.frame_utimes.push_back(frame.utime);
    if (const auto pose = chain.add(r)) run.trajectory.push_back(frame.utime, *pose);
    run.results.push_back(std::move(r));
  }
  return run;
}

RunFigures score(const SequenceRun& run, const Trajectory& gt) {
  RunFigures f = count_by_status(run.results);
  f.median_ms = percentile(run.process_ms, 0.5);
  f.p95_ms = percentile(run.process_ms, 0.95);
  if (gt.empty()) {
    f.not_scored = "no ground truth";
    return f;
  }
  // The first frame's pose is the identity by definition: alone it would score a perfect 0.
  if (f.ok == 0) {
    f.not_scored = "no frame has a motion";
    return f;
  }

  const metrics::EvalOptions options;
  metrics::Evaluation e;
  try {
    e = metrics::evaluate(run.frame_utimes, run.trajectory, gt, options);
  } catch (const metrics::NoOverlapError& error) {
    f.not_scored = error.what();
    return f;
  }
  f.scored_frames = e.association.scored;
  if (f.scored_frames < 2) {
    f.not_scored = std::to_string(f.scored_frames) + " frame(s) with a pose have ground truth (need 2)";
    return f;
  }
  f.scored = true;
  f.ate_rmse_m = e.ate.error_m.rmse;
  f.rpe_translation_mps = e.rpe.translation_mps.rmse;
  f.rpe_rotation_degps = e.rpe.rotation_degps.rmse;
  f.velocity_error_mps = e.velocity.error_mps.mean;
  f.gross = e.velocity.gross.total();
  f.gross_percent = e.velocity.gross.percent();

  // NEES of each relative motion against the ground truth's motion over the same frames.
  double sum = 0.0;
  size_t within = 0;
  for (const VoResult& r : run.results) {
    if (r.status != VoStatus::kOk) continue;
    const auto g_ref = gt.at(r.reference_utime, options.gt_max_gap_us);
    const auto g_cur = gt.at(r.utime, options.gt_max_gap_us);
    if (!g_ref || !g_cur) continue;
    const Vector6d err = pose_error(r.T_reference_current, g_ref->inverse() * *g_cur);
    const double nees = err.dot(r.covariance.ldlt().solve(err));
    if (!std::isfinite(nees)) continue;
    sum += nees;
    within += nees < kChi2_6_95;
    ++f.nees_frames;
  }
  if (f.nees_frames > 0) {
    f.mean_nees = sum / double(f.nees_frames);
    f.nees_within_95 = double(within) / double(f.nees_frames);
  }
  return f;
}

std::string status_summary(const RunFigures& f) {
  std::string out;
  for (size_t i = 0; i < kVoStatusCount; ++i) {
    if (f.by_status[i] == 0) continue;
    out += (out.empty() ? "" : ", ") + std::string(to_string(VoStatus(i))) + " " + std::to_string(f.by_status[i]);
  }
  return out.empty() ? "no frames" : out;
}

void require_usable(const std::vector<VoResult>& results, const std::string& folder) {
  const RunFigures f = count_by_status(results);
  if (f.ok > 0) return;
  std::string first;  // the first frame that failed for a reason other than being the reference
  for (const VoResult& r : results) {
    if (r.status == VoStatus::kNoReference) continue;
    first = "; first failure at " + format_seconds(r.utime) + " s: " + (r.message.empty() ? to_string(r.status) : r.message);
    break;
  }
  throw InputError(folder + ": nothing usable: 0 of " + std::to_string(f.frames) +
                   " frames gave a motion (" + status_summary(f) + ")" + first);
}

std::string stats_json(const SequenceRun& run, const RunFigures& f, const std::string& variant) {
  nlohmann::json j;
  j["variant"] = variant;
  j["frames"] = f.frames;
  j["ok"] = f.ok;
  nlohmann::json by_status = nlohmann::json::object();
  for (size_t i = 0; i < kVoStatusCount; ++i) by_status[to_string(VoStatus(i))] = f.by_status[i];
  j["by_status"] = std::move(by_status);
  j["ms"] = {{"median", f.median_ms}, {"p95", f.p95_ms}};
  // null, not zeros, when nothing was measured: a reader must not mistake it for a perfect run.
  if (f.scored) {
    j["accuracy"] = {{"ate_rmse_m", f.ate_rmse_m},
                     {"rpe_translation_mps", f.rpe_translation_mps},
                     {"rpe_rotation_degps", f.rpe_rotation_degps},
                     {"velocity_error_mps", f.velocity_error_mps},
                     {"gross_percent", f.gross_percent},
                     {"gross", f.gross},
                     {"scored_frames", f.scored_frames}};
  } else {
    j["accuracy"] = nullptr;
    j["not_scored"] = f.not_scored;
  }
  j["nees"] = {{"mean", f.mean_nees}, {"within_95", f.nees_within_95}, {"frames", f.nees_frames}};
  nlohmann::json per_frame = nlohmann::json::array();
  for (size_t i = 0; i < run.results.size(); ++i) {
    const VoResult& r = run.results[i];
    per_frame.push_back({{"utime", r.utime},
                         {"status", to_string(r.status)},
                         {"message", r.message},
                         {"reference_utime", r.reference_utime},
                         {"new_reference", r.new_reference},
                         {"fell_back", r.fell_back_to_previous},
                         {"features", r.num_features},
                         {"with_depth", r.num_features_with_depth},
                         {"matches", r.num_matches},
                         {"inliers", r.num_inliers},
                         {"reprojection_inliers", r.num_reprojection_inliers},
                         {"reprojection_error_px", r.mean_reprojection_error_px},
                         {"pixel_sigma_px", r.pixel_sigma_px},
                         {"fast_threshold", r.fast_threshold},
                         {"ms", run.process_ms[i]}});
  }
  j["per_frame"] = std::move(per_frame);
  return j.dump(1);
}

}  // namespace kestrel::vo
