#pragma once
// A one-page picture of an evaluation, drawn with OpenCV (no Python): the top view (x-y, in
// the ground truth's world) of the ground truth and the aligned estimate, with a grid in
// metres, a scale bar and a legend; below it the ATE position error and the velocity error
// over time, with the gross failures marked.

#include <opencv2/core.hpp>
#include <string>

#include "metrics/evaluate.h"
#include "metrics/options.h"

namespace kestrel::eval {

/// The picture (8-bit BGR, 1000 px wide); `title` is printed above the figures.
cv::Mat render_plot(const metrics::Evaluation& e, const metrics::EvalOptions& options, const std::string& title);

}  // namespace kestrel::eval
