#pragma once
// The evaluation's report: a readable text table, or JSON with the same content. Every
// figure carries its unit in its name; a statistic over no data is printed as "-" (null in
// JSON), never as 0.

#include <nlohmann/json.hpp>
#include <string>

#include "metrics/evaluate.h"
#include "metrics/options.h"
#include "tools/eval/trajectory_input.h"

namespace kestrel::eval {

/// What was compared: the two inputs (after reconcile_frames), where the frame list came
/// from, and the line reconcile_frames returned.
struct ReportInputs {
  const TrajectoryInput& gt;
  const TrajectoryInput& est;
  std::string frames_source;
  std::string compared;
};

std::string text_report(const ReportInputs& inputs, const metrics::Evaluation& e, const metrics::EvalOptions& o);
nlohmann::json json_report(const ReportInputs& inputs, const metrics::Evaluation& e, const metrics::EvalOptions& o);

}  // namespace kestrel::eval
