#pragma once
// The colour sensor model: radiance (in digital numbers) to an 8-bit RGB image through the
// optics point-spread (a 3x3 binomial kernel, the softness of a Kinect's lens and Bayer
// demosaicing, which also anti-aliases polygon edges), vignetting, photon noise (variance
// proportional to the signal) plus read noise, and rounding with saturation.

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

}  // namespace kestrel::sim
