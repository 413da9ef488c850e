#include "drivers/sim/kinect_depth.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "drivers/sim/random.h"

namespace kestrel::sim {
namespace {

constexpr float kUnit = 1.0f / 1024.0f;  // 10 random bits -> [0, 1)

}  // namespace

void make_kinect_depth(const Rasterizer& raster, const std::vector<float>& ir_return, const DepthOptions& o,
                       uint32_t key, cv::Mat& depth_mm) {
  const PinholeCamera& cam = raster.camera();
  const int w = cam.width, h = cam.height;
  depth_mm.create(h, w, CV_16UC1);
  const NormalTable& normal = normal_table();
  const float shift_px = static_cast<float>(cam.fx * o.projector_offset_m);
  const float q = static_cast<float>(inverse_depth_step(o));
  const float inv_min = static_cast<float>(1.0 / o.max_range_m), inv_max = static_cast<float>(1.0 / o.min_range_m);
  const float ret_lo = static_cast<float>(o.return_low), ret_hi = static_cast<float>(o.return_high);
  const float k = static_cast<float>(o.noise_k), jump = static_cast<float>(o.edge_jump);
  const float edge_keep = static_cast<float>(1.0 - o.edge_dropout);
  std::vector<uint8_t> shadow(static_cast<size_t>(w));
  for (int v = 0; v < h; ++v) {
    const uint16_t* ids = raster.ids(v);
    const float* inv = raster.inverse_depth(v);
    const float* ir = ir_return.data() + static_cast<size_t>(v) * w;
    uint16_t* out = depth_mm.ptr<uint16_t>(v);
    // Projector shadow: scanning from the right, a point whose projector column lies right
    // of a nearer point already seen is hidden from the projector.
    float leftmost = std::numeric_limits<float>::infinity();
    for (int u = w - 1; u >= 0; --u) {
      shadow[static_cast<size_t>(u)] = 0;
      if (ids[u] == Rasterizer::kNone) continue;
      const float up = static_cast<float>(u) - shift_px * inv[u];
      if (up > leftmost + 1e-3f) shadow[static_cast<size_t>(u)] = 1;
      else leftmost = std::min(leftmost, up);
    }
    for (int u = 0; u < w; ++u) {
      out[u] = 0;
      const float iz = inv[u];
      if (ids[u] == Rasterizer::kNone || shadow[static_cast<size_t>(u)] || iz < inv_min || iz > inv_max) continue;
      const uint32_t bits = hash32(static_cast<uint32_t>(v * w + u) ^ key);
      const float u1 = static_cast<float>(bits & 1023u) * kUnit;          // weak return
      const float u2 = static_cast<float>((bits >> 10) & 1023u) * kUnit;  // discontinuity
      // Weak IR return.
      const float signal = ir[u] * iz * iz;
      const float p_return = std::clamp((signal - ret_lo) / (ret_hi - ret_lo), 0.0f, 1.0f);
      if (o.noise ? u1 >= p_return : p_return < 0.5f) continue;
      // Far side of a discontinuity (a neighbour markedly nearer).
      const bool edge = (u > 0 && inv[u - 1] - iz > jump * iz) || (u + 1 < w && inv[u + 1] - iz > jump * iz);
      if (edge && (o.noise ? u2 >= edge_keep : edge_keep < 0.5f)) continue;
      float z = 1.0f / iz;
      if (o.noise) z += k * z * z * normal[bits >> 20];
      if (!(z > 0.0f)) continue;
      const float quantised = std::nearbyint(1.0f / (z * q)) * q;  // disparity steps
      if (!(quantised > 0.0f)) continue;
      const float mm = 1000.0f / quantised;
      out[u] = mm >= 65535.0f ? 0 : static_cast<uint16_t>(mm + 0.5f);
    }
  }
}

}  // namespace kestrel::sim
