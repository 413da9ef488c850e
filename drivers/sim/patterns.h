#pragma once
// The pattern generators behind materials.h (internal to the simulator library).
//
// Each returns a CV_32FC3 image (R, G, B, nominally in [0, 1]) of `size` x `size` texels.
// Row index grows with the surface's t axis (upwards on walls), column index with s. Tiling
// patterns are periodic over the image; fitted ones (poster, whiteboard) need not be.

#include <opencv2/core/mat.hpp>

#include "drivers/sim/materials.h"
#include "drivers/sim/random.h"

namespace kestrel::sim::patterns {

// Noise-based surfaces (patterns_noise.cpp).
cv::Mat plaster(const MaterialSpec& spec, int size, Rng& rng);
cv::Mat concrete(const MaterialSpec& spec, int size, Rng& rng);
cv::Mat carpet(const MaterialSpec& spec, int size, Rng& rng);
cv::Mat fabric(const MaterialSpec& spec, int size, Rng& rng);
cv::Mat screen(const MaterialSpec& spec, int size, Rng& rng);

// Structured surfaces (patterns_structured.cpp).
cv::Mat brick(const MaterialSpec& spec, int size, Rng& rng);
cv::Mat wood(const MaterialSpec& spec, int size, Rng& rng);
cv::Mat floor_tiles(const MaterialSpec& spec, int size, Rng& rng);
cv::Mat ceiling_tiles(const MaterialSpec& spec, int size, Rng& rng);
cv::Mat books(const MaterialSpec& spec, int size, Rng& rng);

// Printed and written surfaces (patterns_print.cpp).
cv::Mat poster(const MaterialSpec& spec, int size, Rng& rng);
cv::Mat whiteboard(const MaterialSpec& spec, int size, Rng& rng);

// Shared helpers.
/// rgb = color * luminance, per texel.
cv::Mat tint(const cv::Mat& luminance, const Eigen::Vector3d& color);
/// A uniform value in [0, 1) for integer cell (i, j) of a pattern keyed by `key`.
double cell_random(uint64_t key, int64_t i, int64_t j);
/// Positive modulo.
inline int wrap(int i, int n) { return ((i % n) + n) % n; }

}  // namespace kestrel::sim::patterns
