#pragma once
// The soak's picture, drawn with OpenCV as kestrel's other plots are (no plotting library):
// over simulated minutes, each process's resident memory, its CPU time per camera frame, and
// the whole system's wall time per frame in lock-step beside the VO's own time per frame; the
// warm-up and the start of the fitted stretch are marked.

#include <opencv2/core.hpp>
#include <string>
#include <vector>

#include "tools/soak/soak.h"

namespace kestrel::soak {

/// The picture (8-bit BGR, 1200 px wide); `title` is printed above it.
cv::Mat render_plot(const std::vector<ProcessSample>& samples, const std::vector<ProgressSample>& progress,
                    const Summary& summary, const std::string& title);

}  // namespace kestrel::soak
