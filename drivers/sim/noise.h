#pragma once
// Periodic noise fields from which the procedural textures are made.
//
// A field is a square CV_32FC1 image whose size is a power of two and which tiles seamlessly
// (it is periodic in both directions), so textures built from it can repeat across a surface
// without seams. Fractal noise sums octaves of smooth random noise whose amplitude falls by
// `gain` per octave; gain 0.5 gives the 1/f amplitude spectrum of natural images.

#include <opencv2/core/mat.hpp>

#include "drivers/sim/random.h"

namespace kestrel::sim {

/// The periodic field doubled in size by Catmull-Rom interpolation (each axis separately).
cv::Mat upsample2_periodic(const cv::Mat& field);

/// Fractal noise of `size` x `size` texels: octaves from `coarse_cells` random cells across the
/// tile up to `fine_cells` (both powers of two, coarse <= fine <= size); finer than that the
/// field is only interpolated. Zero mean, unit standard deviation.
cv::Mat fractal_noise(int size, int coarse_cells, int fine_cells, double gain, Rng& rng);

/// Smooth random field with features about size / cells texels across (a single octave).
cv::Mat smooth_noise(int size, int cells, Rng& rng);

/// Rescales `field` in place to zero mean and unit standard deviation.
void standardize(cv::Mat& field);

}  // namespace kestrel::sim
