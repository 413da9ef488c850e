#include "tools/eval/report.h"

#include <fmt/format.h>

#include <cmath>

#include "common/time.h"

namespace kestrel::eval {
namespace {

nlohmann::json to_json(const metrics::Summary& s) {
  return {
      {"count", s.count}, {"rmse", s.rmse}, {"mean", s.mean}, {"median", s.median}, {"max", s.max}};
}

nlohmann::json to_json(const TrajectoryInput& in) {
  const InputDiagnostics& d = in.diagnostics;
  return {{"source", in.source},
          {"format", in.format},
          {"poses", in.trajectory.size()},
          {"frames", in.frame_utimes.size()},
          {"frame", to_string(in.frame)},
          {"diagnostics",
           {{"messages", d.messages},
            {"wrong_type", d.wrong_type},
            {"corrupt", d.corrupt},
            {"invalid_pose", d.invalid_pose},
            {"out_of_order", d.out_of_order},
            {"no_pose", d.no_pose},
            {"unknown_reference", d.unknown_reference},
            {"damage", d.damage}}},
          {"problems", d.problems()}};
}

std::string number(double v) { return std::isfinite(v) ? fmt::format("{:.4f}", v) : "-"; }

std::string row(const std::string& name, const metrics::Summary& s, bool with_max = true) {
  return fmt::format("{:<30} {:>5} {:>9} {:>9} {:>9} {:>9}\n", name, s.count, number(s.rmse),
                     number(s.mean), number(s.median), with_max ? number(s.max) : "");
}

std::string describe(const TrajectoryInput& in) {
  std::string s = fmt::format("{} ({}, {} poses", in.source, in.format, in.trajectory.size());
  if (in.frame_utimes.size() != in.trajectory.size())
    s += fmt::format(" of {} frames", in.frame_utimes.size());
  return s + ")";
}

}  // namespace

std::string text_report(const ReportInputs& in, const metrics::Evaluation& e, const metrics::EvalOptions& o) {
  const metrics::Association& a = e.association;
  const metrics::GrossFailures& g = e.velocity.gross;
  std::string s;
  s += fmt::format("{:<14}{}\n", "ground truth", describe(in.gt));
  s += fmt::format("{:<14}{}\n", "estimate", describe(in.est));
  for (const TrajectoryInput* input : {&in.gt, &in.est})
    for (const std::string& p : input->diagnostics.problems())
      s += fmt::format("{:<14}{}: {}\n", "input problem", input->source, p);
  s += fmt::format("{:<14}{}\n", "compared", in.compared);
  s += fmt::format(
      "{:<14}{} frames from {}: {} scored, {} without an estimate, {} without ground "
      "truth ({} before it, {} after it, {} with no sample within {:g} ms on a side)\n",
      "frames", a.frames.size(), in.frames_source, a.scored, a.no_estimate, a.no_ground_truth(),
      a.no_gt_before_start, a.no_gt_after_end, a.no_gt_in_gap,
      1e-3 * static_cast<double>(o.gt_max_gap_us));
  s += fmt::format("{:<14}{} of {} positions\n", "alignment", metrics::to_string(e.ate.alignment.kind),
                   e.ate.error_m.count);
  s += "\n";
  s += fmt::format("{:<30} {:>5} {:>9} {:>9} {:>9} {:>9}\n", "metric", "n", "rmse", "mean",
                   "median", "max");
  s += row(o.align ? "ATE, aligned (m)" : "ATE, not aligned (m)", e.ate.error_m);
  s += row(fmt::format("RPE translation, {:g} s (m/s)", o.rpe_delta_s), e.rpe.translation_mps);
  s += row(fmt::format("RPE rotation, {:g} s (deg/s)", o.rpe_delta_s), e.rpe.rotation_degps);
  s += row("velocity error (m/s)", e.velocity.error_mps);
  s += row("step error (m)", e.velocity.step_error_m);
  s += fmt::format(
      "{:<30} {} of {} frames ({:.2f} %): {} without an estimate, {} with velocity "
      "error > {:g} m/s",
      "gross failures", g.total(), g.frames, g.percent(), g.no_estimate, g.too_fast,
      o.gross_velocity_mps);
  if (o.gross_after_gt_gap) s += fmt::format(", {} first after a ground-truth gap", g.after_gt_gap);
  s += "\n";
  return s;
}

nlohmann::json json_report(const ReportInputs& in, const metrics::Evaluation& e, const metrics::EvalOptions& o) {
  const metrics::Association& a = e.association;
  const metrics::GrossFailures& g = e.velocity.gross;
  nlohmann::json ate = to_json(e.ate.error_m);
  ate["aligned"] = o.align;
  ate["alignment"] = metrics::to_string(e.ate.alignment.kind);
  return {
      {"ground_truth", to_json(in.gt)},
      {"estimate", to_json(in.est)},
      {"compared", in.compared},
      {"options",
       {{"gt_max_gap_s", to_seconds(o.gt_max_gap_us)},
        {"est_max_gap_s", to_seconds(o.est_max_gap_us)},
        {"align", o.align},
        {"rpe_delta_s", o.rpe_delta_s},
        {"rpe_tolerance_s", o.rpe_tolerance_s},
        {"gross_velocity_mps", o.gross_velocity_mps},
        {"gross_after_gt_gap", o.gross_after_gt_gap}}},
      {"frames",
       {{"source", in.frames_source},
        {"count", a.frames.size()},
        {"scored", a.scored},
        {"no_estimate", a.no_estimate},
        {"no_ground_truth",
         {{"total", a.no_ground_truth()},
          {"before_start", a.no_gt_before_start},
          {"after_end", a.no_gt_after_end},
          {"in_gap", a.no_gt_in_gap}}}}},
      {"ate_m", ate},
      {"rpe",
       {{"delta_s", o.rpe_delta_s},
        {"pairs", e.rpe.pairs},
        {"frames_without_partner", e.rpe.no_partner},
        {"translation_mps", to_json(e.rpe.translation_mps)},
        {"rotation_degps", to_json(e.rpe.rotation_degps)}}},
      {"velocity_error_mps", to_json(e.velocity.error_mps)},
      {"step_error_m", to_json(e.velocity.step_error_m)},
      {"largest_step_s", e.velocity.step_error_m.count == 0 ? nlohmann::json(nullptr)
                                                           : nlohmann::json(to_seconds(e.velocity.largest_step_utime))},
      {"gross_failures",
       {{"frames", g.frames},
        {"no_estimate", g.no_estimate},
        {"velocity_too_large", g.too_fast},
        {"after_gt_gap", g.after_gt_gap},
        {"total", g.total()},
        {"percent", g.percent()}}},
  };
}

}  // namespace kestrel::eval
