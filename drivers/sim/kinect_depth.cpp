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
  const bool noise = o.noise;
  const float k_used = noise ? k : 0.0f;
  // Without noise every draw is 0.5: the model's mean behaviour.
  const float draw = noise ? 1.0f : 0.0f, fixed_draw = noise ? 0.0f : 0.5f;
  // Row buffers, per thread. inv is copied with a zero on each side: a missing neighbour is
  // never "markedly nearer" (0 - iz > jump iz is false for iz > 0).
  thread_local std::vector<float> padded;
  thread_local std::vector<uint8_t> usable;
  padded.assign(static_cast<size_t>(w) + 2, 0.0f);
  usable.resize(static_cast<size_t>(w));
  thread_local std::vector<float> columns;
  thread_local std::vector<uint8_t> lits;
  thread_local std::vector<float> pixel_u;  // 0, 1, ..., w - 1 as floats (keeps the loop vectorisable)
  columns.resize(static_cast<size_t>(w));
  if (pixel_u.size() != static_cast<size_t>(w)) {
    pixel_u.resize(static_cast<size_t>(w));
    for (int u = 0; u < w; ++u) pixel_u[static_cast<size_t>(u)] = static_cast<float>(u);
  }
  const float* fu = pixel_u.data();
  lits.resize(static_cast<size_t>(w));
  uint8_t* ok = usable.data();
  float* column = columns.data();
  uint8_t* lit = lits.data();
  for (int v = 0; v < h; ++v) {
    const float* inv = raster.inverse_depth(v);
    const float* ir = ir_return.data() + static_cast<size_t>(v) * w;
    uint16_t* out = depth_mm.ptr<uint16_t>(v);
    // Projector shadow: scanning from the right, a point whose projector column lies right
    // of a nearer point already seen is hidden from the projector. The projector columns
    // (+inf where nothing is seen) are a vectorised loop; the scan is a branch-free running
    // minimum (a hidden point's column is right of the minimum, so min() leaves it as it is).
    const float inf = std::numeric_limits<float>::infinity();
    // (inv > 0 exactly where a surface is seen: the rasteriser's depth test starts from 0.)
    for (int u = 0; u < w; ++u) {
      const float up = fu[u] - shift_px * inv[u];
      column[u] = inv[u] > 0.0f ? up : inf;
    }
    float leftmost = inf;
    for (int u = w - 1; u >= 0; --u) {
      const float up = column[u];
      lit[u] = !(up > leftmost + 1e-3f);
      leftmost = std::min(leftmost, up);
    }
    for (int u = 0; u < w; ++u)
      ok[u] = static_cast<uint8_t>((inv[u] > 0.0f) & (lit[u] != 0) & (inv[u] >= inv_min) & (inv[u] <= inv_max));
    std::copy(inv, inv + w, padded.begin() + 1);
    const float* pad = padded.data() + 1;
    // Everything else is per pixel and branch-free, so the compiler vectorises it.
    const uint32_t row_key = static_cast<uint32_t>(v * w);
    for (int u = 0; u < w; ++u) {
      const float iz = pad[u];
      const uint32_t bits = hash32((row_key + static_cast<uint32_t>(u)) ^ key);
      const float u1 = static_cast<float>(bits & 1023u) * kUnit;          // weak return
      const float u2 = static_cast<float>((bits >> 10) & 1023u) * kUnit;  // discontinuity
      // Weak IR return.
      const float signal = ir[u] * iz * iz;
      const float p_return = std::min(std::max((signal - ret_lo) / (ret_hi - ret_lo), 0.0f), 1.0f);
      // Draws compared with '>' / '<' alike in both modes, so there is no branch.
      const bool returned = (draw * u1 + fixed_draw) < p_return;
      // Far side of a discontinuity (a neighbour markedly nearer).
      const bool edge = (pad[u - 1] - iz > jump * iz) | (pad[u + 1] - iz > jump * iz);
      const bool dropped = edge & ((draw * u2 + fixed_draw) > edge_keep);
      const float z_true = 1.0f / std::max(iz, 1e-6f);
      const float z = z_true + k_used * z_true * z_true * normal[bits >> 20];
      // Quantised in disparity steps (round half up; the argument is positive, < 2^31).
      const float steps = static_cast<float>(static_cast<int32_t>(1.0f / (std::max(z, 1e-3f) * q) + 0.5f));
      const float mm = 1000.0f / (std::max(steps, 1.0f) * q);
      const bool good = (ok[u] != 0) & returned & !dropped & (z > 0.0f) & (steps > 0.0f) & (mm < 65535.0f);
      out[u] = static_cast<uint16_t>(static_cast<int32_t>(good ? mm + 0.5f : 0.0f));
    }
  }
}

}  // namespace kestrel::sim
