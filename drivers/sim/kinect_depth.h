#pragma once
// The Kinect's depth sensor model, applied to exact per-pixel depth.
//
// A reading is missing beyond the range limits; in the projector's shadow (the projector sits
// beside the camera, so a band beside every foreground edge gets no pattern); on the far side
// of depth discontinuities (the block matcher fails there); and where the IR return
// albedo * cos(incidence) / z^2 is weak (dark, far or grazing surfaces). A present reading
// gets Gaussian noise sigma_z = k z^2 (Khoshelham & Elberink 2012) and is quantised in
// disparity (1/z in steps of 1 / (subpixel * f_ir * baseline)), so the depth step grows as z^2,
// as the Kinect's does. Output: millimetres, 0 = no reading.

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "drivers/sim/camera_options.h"
#include "drivers/sim/rasterizer.h"

namespace kestrel::sim {

/// Depth quantisation step of inverse depth, 1/m.
inline double inverse_depth_step(const DepthOptions& o) { return 1.0 / (o.subpixel * o.ir_focal_px * o.baseline_m); }

/// Fills depth_mm (CV_16UC1, camera size) from the rasterised view. `ir_return` holds
/// albedo * cos(incidence) per pixel. Random draws are keyed by `key` and the pixel index.
void make_kinect_depth(const Rasterizer& raster, const std::vector<float>& ir_return, const DepthOptions& options,
                       uint32_t key, cv::Mat& depth_mm);

}  // namespace kestrel::sim
