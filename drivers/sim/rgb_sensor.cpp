#include "drivers/sim/rgb_sensor.h"

#include <algorithm>
#include <cmath>

#include "drivers/sim/random.h"

namespace kestrel::sim {
namespace {

// In-place [1 2 1] / 4 blur along each row, edges clamped (the vertical pass is done on the
// fly in expose_rgb, from three of these rows).
void blur_rows(std::vector<float>& plane, std::vector<float>& row, int w, int h) {
  row.resize(static_cast<size_t>(w));
  for (int v = 0; v < h; ++v) {
    float* p = plane.data() + static_cast<size_t>(v) * w;
    std::copy(p, p + w, row.begin());
    const float* in = row.data();
    p[0] = 0.75f * in[0] + 0.25f * in[std::min(1, w - 1)];
    for (int u = 1; u + 1 < w; ++u) p[u] = 0.25f * (in[u - 1] + in[u + 1]) + 0.5f * in[u];
    if (w > 1) p[w - 1] = 0.75f * in[w - 1] + 0.25f * in[w - 2];
  }
}

// Row buffers, per thread so that concurrent renderers never share them.
struct RowBuffers {
  std::vector<float> row, fall_u, value, normal;
  std::vector<uint32_t> bits;
};

}  // namespace

void expose_rgb(std::vector<float> (&planes)[3], const PinholeCamera& cam, const RgbOptions& o, uint32_t key,
                cv::Mat& rgb) {
  const int w = cam.width, h = cam.height;
  thread_local RowBuffers buf;
  const size_t n = static_cast<size_t>(w);
  if (o.optics_blur)
    for (auto& p : planes) blur_rows(p, buf.row, w, h);
  // Vignetting 1 - a (x^2 + y^2) / 2 with x, y = -1..1 across the image: 1 - a at the corners.
  buf.fall_u.resize(n);
  buf.value.resize(n);
  buf.normal.resize(n);
  buf.bits.resize(n);
  const float a = static_cast<float>(o.vignetting) * 0.5f;
  for (int u = 0; u < w; ++u) {
    const float x = static_cast<float>((u - cam.cx) / (0.5 * w));
    buf.fall_u[static_cast<size_t>(u)] = a * x * x;
  }
  const NormalTable& normal = normal_table();
  const float read_var = static_cast<float>(o.read_noise_dn * o.read_noise_dn);
  const float shot = static_cast<float>(o.shot_noise_dn);
  rgb.create(h, w, CV_8UC3);
  // Separate simple loops over a row, so the compiler vectorises all but the table lookup.
  float* value = buf.value.data();
  float* noise = buf.normal.data();
  uint32_t* bits = buf.bits.data();
  const float* fall_u = buf.fall_u.data();
  for (int v = 0; v < h; ++v) {
    const float y = static_cast<float>((v - cam.cy) / (0.5 * h));
    const float gain_v = 1.0f - a * y * y;
    const uint32_t row_key = static_cast<uint32_t>(v * w);
    if (o.noise)
      for (int u = 0; u < w; ++u) bits[u] = hash32((row_key + static_cast<uint32_t>(u)) ^ key);
    uchar* out = rgb.ptr<uchar>(v);
    for (int c = 0; c < 3; ++c) {
      const float* mid = planes[c].data() + static_cast<size_t>(v) * w;
      if (o.optics_blur) {
        const float* up = planes[c].data() + static_cast<size_t>(std::max(v - 1, 0)) * w;
        const float* down = planes[c].data() + static_cast<size_t>(std::min(v + 1, h - 1)) * w;
        for (int u = 0; u < w; ++u) value[u] = (0.25f * (up[u] + down[u]) + 0.5f * mid[u]) * (gain_v - fall_u[u]);
      } else {
        for (int u = 0; u < w; ++u) value[u] = mid[u] * (gain_v - fall_u[u]);
      }
      if (o.noise) {
        const int shift = 10 * c;
        for (int u = 0; u < w; ++u) noise[u] = normal[bits[u] >> shift];
        for (int u = 0; u < w; ++u) value[u] += std::sqrt(read_var + shot * std::max(value[u], 0.0f)) * noise[u];
      }
      for (int u = 0; u < w; ++u) out[3 * u + c] = static_cast<uchar>(std::min(std::max(value[u] + 0.5f, 0.0f), 255.0f));
    }
  }
}

}  // namespace kestrel::sim
