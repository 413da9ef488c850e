#include "drivers/sim/rgb_sensor.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "drivers/sim/random.h"

namespace kestrel::sim {
namespace {

// [1 2 1] / 4 blur of one row, edges clamped (the vertical pass is done on the fly in
// expose_rgb, from three of these rows).
void blur_row(const float* in, float* p, int w) {
  p[0] = 0.75f * in[0] + 0.25f * in[std::min(1, w - 1)];
  for (int u = 1; u + 1 < w; ++u) p[u] = 0.25f * (in[u - 1] + in[u + 1]) + 0.5f * in[u];
  if (w > 1) p[w - 1] = 0.75f * in[w - 1] + 0.25f * in[w - 2];
}

// Row buffers, per thread so that concurrent renderers never share them.
struct RowBuffers {
  std::vector<float> blurred;  // 3 channels x 3 rows (a ring over v - 1, v, v + 1)
  std::vector<float> fall_u, value, normal;
  std::vector<uint32_t> bits, packed;
};

}  // namespace

float auto_exposure_gain(const std::vector<float> (&planes)[3], int width, int height, double max_mean_grey) {
  if (!(max_mean_grey > 0.0)) return 1.0f;
  constexpr int kStep = 4;
  thread_local std::vector<float> grey;  // per thread, as RowBuffers: no allocation per frame
  grey.clear();
  for (int v = kStep / 2; v < height; v += kStep)
    for (int u = kStep / 2; u < width; u += kStep) {
      const size_t i = static_cast<size_t>(v) * static_cast<size_t>(width) + static_cast<size_t>(u);
      const float y = 0.299f * planes[0][i] + 0.587f * planes[1][i] + 0.114f * planes[2][i];
      if (std::isfinite(y)) grey.push_back(y);  // (the renderer gives none other; a NaN must not meter)
    }
  if (grey.empty()) return 1.0f;
  const auto clipped_mean = [&](double gain) {
    double sum = 0.0;
    for (const float y : grey) sum += std::min(gain * static_cast<double>(y), 255.0);
    return sum / static_cast<double>(grey.size());
  };
  if (clipped_mean(1.0) <= max_mean_grey) return 1.0f;
  // The clipped mean grows with the gain: bisect for the gain that gives max_mean_grey.
  double low = 0.0, high = 1.0;
  for (int i = 0; i < 60 && high - low > 1e-4 * high; ++i) {
    const double mid = 0.5 * (low + high);
    (clipped_mean(mid) > max_mean_grey ? high : low) = mid;
  }
  return static_cast<float>(low);
}

void expose_rgb(std::vector<float> (&planes)[3], const PinholeCamera& cam, const RgbOptions& o, uint32_t key,
                cv::Mat& rgb) {
  const int w = cam.width, h = cam.height;
  thread_local RowBuffers buf;
  const size_t n = static_cast<size_t>(w);
  // Horizontally blurred rows, computed once each as the vertical pass first needs them.
  buf.blurred.resize(9 * n);
  auto blurred = [&](int c, int r) { return buf.blurred.data() + (static_cast<size_t>(c) * 3 + static_cast<size_t>(r % 3)) * n; };
  auto blur_into_ring = [&](int r) {
    for (int c = 0; c < 3; ++c) blur_row(planes[c].data() + static_cast<size_t>(r) * n, blurred(c, r), w);
  };
  // Vignetting 1 - a (x^2 + y^2) / 2 with x, y = -1..1 across the image: 1 - a at the corners.
  buf.fall_u.resize(n);
  buf.value.resize(3 * n);
  buf.normal.resize(3 * n);
  buf.packed.resize(n);
  buf.bits.resize(n);
  const float a = static_cast<float>(o.vignetting) * 0.5f;
  for (int u = 0; u < w; ++u) {
    const float x = static_cast<float>((u - cam.cx) / (0.5 * w));
    buf.fall_u[static_cast<size_t>(u)] = a * x * x;
  }
  const NormalTable& normal = normal_table();
  const float exposure_gain = auto_exposure_gain(planes, w, h, o.max_mean_grey);
  const float read_var = static_cast<float>(o.read_noise_dn * o.read_noise_dn);
  const float shot = static_cast<float>(o.shot_noise_dn);
  rgb.create(h, w, CV_8UC3);
  // Separate simple loops over a row, so the compiler vectorises all but the table lookup.
  float* noise = buf.normal.data();
  uint32_t* bits = buf.bits.data();
  const float* fall_u = buf.fall_u.data();
  if (o.optics_blur) {
    blur_into_ring(0);
    if (h > 1) blur_into_ring(1);
  }
  for (int v = 0; v < h; ++v) {
    const float y = static_cast<float>((v - cam.cy) / (0.5 * h));
    const float gain_v = 1.0f - a * y * y;
    const uint32_t row_key = static_cast<uint32_t>(v * w);
    if (o.optics_blur && v > 0 && v + 1 < h) blur_into_ring(v + 1);
    if (o.noise) {
      for (int u = 0; u < w; ++u) bits[u] = hash32((row_key + static_cast<uint32_t>(u)) ^ key);
      // The table lookups (not vectorisable) for all three channels in one pass.
      float* n0 = noise;
      float* n1 = noise + n;
      float* n2 = noise + 2 * n;
      for (int u = 0; u < w; ++u) {
        const uint32_t b = bits[u];
        n0[u] = normal[b];
        n1[u] = normal[b >> 10];
        n2[u] = normal[b >> 20];
      }
    }
    for (int c = 0; c < 3; ++c) {
      float* value = buf.value.data() + static_cast<size_t>(c) * n;
      if (o.optics_blur) {
        const float* up = blurred(c, std::max(v - 1, 0));
        const float* mid = blurred(c, v);
        const float* down = blurred(c, std::min(v + 1, h - 1));
        for (int u = 0; u < w; ++u) value[u] = (0.25f * (up[u] + down[u]) + 0.5f * mid[u]) * (gain_v - fall_u[u]);
      } else {
        const float* mid = planes[c].data() + static_cast<size_t>(v) * w;
        for (int u = 0; u < w; ++u) value[u] = mid[u] * (gain_v - fall_u[u]);
      }
      // Only where the auto-exposure acts: elsewhere the frame is bit for bit the fixed exposure's.
      if (exposure_gain != 1.0f)
        for (int u = 0; u < w; ++u) value[u] *= exposure_gain;
      if (o.noise) {
        const float* nc = noise + static_cast<size_t>(c) * n;
        for (int u = 0; u < w; ++u) value[u] += std::sqrt(read_var + shot * std::max(value[u], 0.0f)) * nc[u];
      }
      for (int u = 0; u < w; ++u) value[u] = std::min(std::max(value[u] + 0.5f, 0.0f), 255.0f);
    }
    const float* r = buf.value.data();
    const float* g = r + n;
    const float* b = g + n;
    uchar* out = rgb.ptr<uchar>(v);
    // R | G << 8 | B << 16 per pixel (vectorised), then one overlapping 4-byte store per
    // pixel (the next pixel's store overwrites the spare byte; the last pixel stores 3).
    uint32_t* packed = buf.packed.data();
    for (int u = 0; u < w; ++u)
      packed[u] = static_cast<uint32_t>(static_cast<int32_t>(r[u])) | static_cast<uint32_t>(static_cast<int32_t>(g[u])) << 8 |
                  static_cast<uint32_t>(static_cast<int32_t>(b[u])) << 16;
#if defined(__BYTE_ORDER__) && __BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__
    for (int u = 0; u + 1 < w; ++u) std::memcpy(out + 3 * u, packed + u, 4);
    if (w > 0) std::memcpy(out + 3 * (w - 1), packed + (w - 1), 3);
#else
    for (int u = 0; u < w; ++u)
      for (int c = 0; c < 3; ++c) out[3 * u + c] = static_cast<uchar>(packed[u] >> (8 * c));
#endif
  }
}

}  // namespace kestrel::sim
