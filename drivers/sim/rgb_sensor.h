#pragma once
// The colour sensor model: radiance (in digital numbers) to an 8-bit RGB image through the
// auto-exposure (below), the optics point-spread (a 3x3 binomial kernel, the softness of a
// Kinect's lens and Bayer demosaicing, which also anti-aliases polygon edges), vignetting,
// photon noise (variance proportional to the signal) plus read noise, and rounding with
// saturation.
//
// Auto-exposure: a Kinect's colour camera sets its exposure from what it sees, and TUM's
// freiburg1 frames keep a mean grey level of 135-138 (median), never above 155 / 161 (fr1_xyz /
// fr1_rpy, `kestrel sim-realism`). A fixed exposure does not: near the simulated lamps the
// frames washed out (stata's median frame had 76 % of its pixels at 250+). Where an image's
// mean grey, clipped as the sensor clips it, would be above RgbOptions::max_mean_grey, the
// exposure is lowered until the metered mean is that; elsewhere it stays as set, so a frame within the range
// a Kinect gives is rendered exactly as without it. Instantaneous (no lag over frames): a frame
// depends on its own pose only. Dim frames are not brightened (not modelled).

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "common/camera.h"
#include "drivers/sim/camera_options.h"

namespace kestrel::sim {

/// `planes` holds R, G, B radiance per pixel (row-major, camera size); they are not modified.
/// Writes rgb (CV_8UC3, R, G, B). Noise draws are keyed by `key` and the pixel index.
void expose_rgb(std::vector<float> (&planes)[3], const PinholeCamera& camera, const RgbOptions& options,
                uint32_t key, cv::Mat& rgb);

/// The auto-exposure's factor on the exposure for `planes` (width x height; see the top of this
/// file): 1 when `max_mean_grey` <= 0 or the clipped mean grey (metered on every 4th pixel of
/// every 4th row, before the optics and the vignetting; non-finite values are not metered) is
/// at most `max_mean_grey`; else the factor in [0, 1) that brings the metered mean to
/// `max_mean_grey` (within 1e-4 of it, relative). The frame that comes out is a little darker
/// still (vignetting): ~148 for 160.
float auto_exposure_gain(const std::vector<float> (&planes)[3], int width, int height, double max_mean_grey);

}  // namespace kestrel::sim
