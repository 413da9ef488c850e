#pragma once
// How each surface looks: which texture, where it sits on the surface, the aperiodic wear
// layer over it, and its light map. Everything is a function of surface coordinates (s, t),
// so a point looks the same from any view.
//
// Albedo at (s, t) = mean + detail * (T(s, t) - mean), times (1 + wear_gain * W(R (s, t))),
// where T is the material's texture, W the shared wear texture under a per-surface rotation R
// (whose period is incommensurate with T's, so tiled surfaces never repeat exactly), and
// `detail` the surface's texture density. Radiance = albedo * shade(s, t).

#include <Eigen/Core>
#include <algorithm>
#include <memory>
#include <vector>

#include "drivers/sim/collision.h"
#include "drivers/sim/materials.h"
#include "drivers/sim/surface.h"
#include "drivers/sim/texture.h"

namespace kestrel::sim {

/// A scalar field over a surface sampled on nodes `cell` metres apart in s and t, bilinear
/// in between and clamped at the edges.
struct ShadeMap {
  int cols = 1;
  int rows = 1;
  float inv_cell = 1.0f;  ///< nodes per metre
  std::vector<float> values{1.0f};

  float at(float s, float t) const {
    const float x = std::clamp(s * inv_cell, 0.0f, static_cast<float>(cols - 1));
    const float y = std::clamp(t * inv_cell, 0.0f, static_cast<float>(rows - 1));
    const int x0 = std::min(static_cast<int>(x), cols - 2 < 0 ? 0 : cols - 2);
    const int y0 = std::min(static_cast<int>(y), rows - 2 < 0 ? 0 : rows - 2);
    const int x1 = std::min(x0 + 1, cols - 1), y1 = std::min(y0 + 1, rows - 1);
    const float ax = x - static_cast<float>(x0), ay = y - static_cast<float>(y0);
    const float* v = values.data();
    const float top = v[y0 * cols + x0] + ax * (v[y0 * cols + x1] - v[y0 * cols + x0]);
    const float bottom = v[y1 * cols + x0] + ax * (v[y1 * cols + x1] - v[y1 * cols + x0]);
    return top + ay * (bottom - top);
  }
};

struct SurfaceLook {
  std::shared_ptr<const MipTexture> texture;
  float texels_per_m_s = 1.0f;  ///< level-0 texels per metre along s
  float texels_per_m_t = 1.0f;  ///< ... along t
  float offset_s = 0.0f;        ///< texels added to s * texels_per_m_s
  float offset_t = 0.0f;
  float detail = 1.0f;          ///< texture density (0 = blank)
  Eigen::Vector3f mean = Eigen::Vector3f::Zero();  ///< texture mean, 0..255
  float wear_gain = 0.0f;       ///< relative amplitude of the wear layer
  float wear_m[4] = {1, 0, 0, 1};  ///< (s, t) metres -> wear texels: [m0 m1; m2 m3]
  float wear_offset[2] = {0, 0};
  ShadeMap shade;
  double features_per_m2 = 0.0;
};

/// Texture side of the wear layer, and its texel size (metres).
constexpr int kWearSize = 1024;
constexpr double kWearTexelM = 0.00173;

/// The shared wear texture (grey, values around 128), deterministic from `seed`.
std::shared_ptr<const MipTexture> make_wear_texture(uint64_t seed);

/// Textures and placement of every surface. Tiling materials share one texture each;
/// fitted ones get one per surface. Shade maps are left flat (see compute_shade_maps).
std::vector<SurfaceLook> make_looks(const std::vector<Surface>& surfaces,
                                    const std::vector<MaterialSpec>& materials, uint64_t seed);

/// FAST corners (threshold 20, non-maximum suppression) per m^2 of the surface's texture at
/// the mip level a 525 px focal length sees from 2 m, under irradiance 1.
double measure_feature_density(const SurfaceLook& look);

}  // namespace kestrel::sim
