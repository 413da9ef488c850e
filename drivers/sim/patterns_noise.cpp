// Noise-based surfaces: painted plaster, concrete, carpet, fabric, dark screens. Amplitudes are
// relative albedo variations; `contrast` scales them all.

#include <algorithm>
#include <cmath>

#include "common/numbers.h"
#include "drivers/sim/noise.h"
#include "drivers/sim/patterns.h"

namespace kestrel::sim::patterns {
namespace {
}  // namespace

cv::Mat tint(const cv::Mat& luminance, const Eigen::Vector3d& color) {
  cv::Mat rgb(luminance.size(), CV_32FC3);
  const cv::Vec3f c(static_cast<float>(color.x()), static_cast<float>(color.y()),
                    static_cast<float>(color.z()));
  for (int r = 0; r < luminance.rows; ++r) {
    const float* l = luminance.ptr<float>(r);
    cv::Vec3f* o = rgb.ptr<cv::Vec3f>(r);
    for (int k = 0; k < luminance.cols; ++k) o[k] = c * l[k];
  }
  return rgb;
}

double cell_random(uint64_t key, int64_t i, int64_t j) {
  const uint64_t h = derive(derive(key, static_cast<uint64_t>(i)), static_cast<uint64_t>(j));
  return static_cast<double>(h >> 11) * 0x1.0p-53;
}

// Painted wall: faint undulation and roller stipple, nearly featureless by design.
cv::Mat plaster(const MaterialSpec& spec, int size, Rng& rng) {
  const float k = static_cast<float>(spec.contrast);
  cv::Mat lum = fractal_noise(size, 4, size / 4, 0.6, rng) * static_cast<double>(0.03f * k) +
                fractal_noise(size, size / 2, size, 0.7, rng) * static_cast<double>(0.015f * k) + 1.0;
  return tint(lum, spec.color);
}

// Concrete: blotchy multi-octave variation, stains and dark pores of a few millimetres.
cv::Mat concrete(const MaterialSpec& spec, int size, Rng& rng) {
  const float k = static_cast<float>(spec.contrast);
  cv::Mat lum = fractal_noise(size, 2, size / 2, 0.62, rng) * static_cast<double>(0.11f * k) +
                fractal_noise(size, size / 2, size, 0.5, rng) * static_cast<double>(0.05f * k) + 1.0;
  const cv::Mat pores = fractal_noise(size, size / 4, size / 2, 0.8, rng);
  const cv::Mat stains = smooth_noise(size, 8, rng);
  for (int r = 0; r < size; ++r) {
    float* l = lum.ptr<float>(r);
    const float* p = pores.ptr<float>(r);
    const float* s = stains.ptr<float>(r);
    for (int c = 0; c < size; ++c) {
      if (p[c] > 2.2f) l[c] *= 1.0f - 0.45f * k * std::min(1.0f, p[c] - 2.2f + 0.4f);
      if (s[c] > 1.2f) l[c] *= 1.0f - 0.08f * k * (s[c] - 1.2f);
    }
  }
  return tint(lum, spec.color);
}

// Loop-pile carpet: fine fibre texture, mottling, and flecks of a second colour.
cv::Mat carpet(const MaterialSpec& spec, int size, Rng& rng) {
  const float k = static_cast<float>(spec.contrast);
  const cv::Mat fibres = fractal_noise(size, size / 2, size, 0.8, rng);
  const cv::Mat mottle = fractal_noise(size, 4, size / 8, 0.6, rng);
  const cv::Mat flecks = fractal_noise(size, size / 4, size / 2, 0.9, rng);
  const cv::Vec3f base(static_cast<float>(spec.color.x()), static_cast<float>(spec.color.y()),
                       static_cast<float>(spec.color.z()));
  const cv::Vec3f fleck_color = cv::Vec3f(0.85f, 0.8f, 0.7f) - base * 0.3f;
  cv::Mat rgb(size, size, CV_32FC3);
  for (int r = 0; r < size; ++r) {
    const float* f = fibres.ptr<float>(r);
    const float* m = mottle.ptr<float>(r);
    const float* x = flecks.ptr<float>(r);
    cv::Vec3f* o = rgb.ptr<cv::Vec3f>(r);
    for (int c = 0; c < size; ++c) {
      const float lum = 1.0f + k * (0.16f * f[c] + 0.08f * m[c]);
      o[c] = x[c] > 2.0f ? fleck_color * (0.9f + 0.1f * f[c]) : base * lum;
    }
  }
  return rgb;
}

// Woven fabric (cubicle partitions, seats): a regular weave a few millimetres across.
cv::Mat fabric(const MaterialSpec& spec, int size, Rng& rng) {
  const float k = static_cast<float>(spec.contrast);
  const cv::Mat slub = fractal_noise(size, 8, size / 2, 0.7, rng);
  const double cycles = size / 2.0;  // a thread every two texels
  cv::Mat lum(size, size, CV_32FC1);
  for (int r = 0; r < size; ++r) {
    const float* s = slub.ptr<float>(r);
    float* l = lum.ptr<float>(r);
    const double wy = std::sin(kTwoPi * cycles * (r + 0.5) / size);
    for (int c = 0; c < size; ++c) {
      const double wx = std::sin(kTwoPi * cycles * (c + 0.5) / size);
      l[c] = 1.0f + k * (0.06f * static_cast<float>(wx * wy) + 0.07f * s[c]);
    }
  }
  return tint(lum, spec.color);
}

// Switched-off monitor or glossy black panel: dark, almost uniform (Kinect depth drops out).
cv::Mat screen(const MaterialSpec& spec, int size, Rng& rng) {
  const float k = static_cast<float>(spec.contrast);
  cv::Mat lum = fractal_noise(size, 2, 16, 0.6, rng) * static_cast<double>(0.15f * k) + 1.0;
  return tint(lum, spec.color);
}

}  // namespace kestrel::sim::patterns
