#include "drivers/sim/rgb_sensor.h"

#include <algorithm>
#include <cmath>

#include "drivers/sim/random.h"

namespace kestrel::sim {
namespace {

// In-place [1 2 1] / 4 blur along rows then columns, edges clamped.
void binomial_blur(std::vector<float>& plane, std::vector<float>& scratch, int w, int h) {
  scratch.resize(plane.size());
  for (int v = 0; v < h; ++v) {
    const float* in = plane.data() + static_cast<size_t>(v) * w;
    float* out = scratch.data() + static_cast<size_t>(v) * w;
    out[0] = 0.75f * in[0] + 0.25f * in[std::min(1, w - 1)];
    for (int u = 1; u + 1 < w; ++u) out[u] = 0.25f * (in[u - 1] + in[u + 1]) + 0.5f * in[u];
    if (w > 1) out[w - 1] = 0.75f * in[w - 1] + 0.25f * in[w - 2];
  }
  for (int v = 0; v < h; ++v) {
    const float* up = scratch.data() + static_cast<size_t>(std::max(v - 1, 0)) * w;
    const float* mid = scratch.data() + static_cast<size_t>(v) * w;
    const float* down = scratch.data() + static_cast<size_t>(std::min(v + 1, h - 1)) * w;
    float* out = plane.data() + static_cast<size_t>(v) * w;
    for (int u = 0; u < w; ++u) out[u] = 0.25f * (up[u] + down[u]) + 0.5f * mid[u];
  }
}

}  // namespace

void expose_rgb(std::vector<float> (&planes)[3], const PinholeCamera& cam, const RgbOptions& o, uint32_t key,
                cv::Mat& rgb) {
  const int w = cam.width, h = cam.height;
  if (o.optics_blur) {
    std::vector<float> scratch;
    for (auto& p : planes) binomial_blur(p, scratch, w, h);
  }
  // Vignetting 1 - a (x^2 + y^2) / 2 with x, y = -1..1 across the image: 1 - a at the corners.
  std::vector<float> fall_u(static_cast<size_t>(w));
  const float a = static_cast<float>(o.vignetting) * 0.5f;
  for (int u = 0; u < w; ++u) {
    const float x = static_cast<float>((u - cam.cx) / (0.5 * w));
    fall_u[static_cast<size_t>(u)] = a * x * x;
  }
  const NormalTable& normal = normal_table();
  const float read_var = static_cast<float>(o.read_noise_dn * o.read_noise_dn);
  const float shot = static_cast<float>(o.shot_noise_dn);
  rgb.create(h, w, CV_8UC3);
  for (int v = 0; v < h; ++v) {
    const float y = static_cast<float>((v - cam.cy) / (0.5 * h));
    const float fall_v = a * y * y;
    uchar* out = rgb.ptr<uchar>(v);
    for (int u = 0; u < w; ++u) {
      const size_t i = static_cast<size_t>(v) * w + u;
      const float gain = 1.0f - fall_u[static_cast<size_t>(u)] - fall_v;
      const uint32_t bits = o.noise ? hash32(static_cast<uint32_t>(i) ^ key) : 0u;
      for (int c = 0; c < 3; ++c) {
        float value = planes[c][i] * gain;
        if (o.noise) value += std::sqrt(read_var + shot * std::max(value, 0.0f)) * normal[bits >> (10 * c)];
        out[3 * u + c] = static_cast<uchar>(std::clamp(value + 0.5f, 0.0f, 255.0f));
      }
    }
  }
}

}  // namespace kestrel::sim
