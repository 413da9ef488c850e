#include "drivers/sim/lighting.h"

#include <algorithm>
#include <cmath>

#include "drivers/sim/random.h"
#include "drivers/sim/world.h"

namespace kestrel::sim {
namespace {

// Direct irradiance at p (normal n) from every light in range that p can see.
double direct_irradiance(const Eigen::Vector3d& p, const Eigen::Vector3d& n, const std::vector<Light>& lights,
                         const CollisionIndex& index, const LightingOptions& o) {
  double e = 0.0;
  for (const Light& light : lights) {
    const Eigen::Vector3d to_light = light.position - p;
    const double d = to_light.norm();
    if (d > o.range_m || d < 1e-6) continue;
    const double cos_theta = n.dot(to_light) / d;
    if (cos_theta <= 0.0) continue;
    if (index.raycast(p, to_light / d, d - 0.02)) continue;  // in shadow
    e += light.power * cos_theta / (d * d + o.source_radius_m * o.source_radius_m);
  }
  return e;
}

// A smooth random field on a cols x rows grid: white noise blurred twice by a 3x3 mean,
// rescaled to unit standard deviation.
std::vector<float> smooth_field(int cols, int rows, Rng& rng) {
  std::vector<float> v(static_cast<size_t>(cols) * rows);
  for (float& x : v) x = static_cast<float>(rng.normal());
  for (int pass = 0; pass < 2; ++pass) {
    std::vector<float> out(v.size());
    for (int y = 0; y < rows; ++y)
      for (int x = 0; x < cols; ++x) {
        float sum = 0.0f;
        int count = 0;
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int xx = x + dx, yy = y + dy;
            if (xx < 0 || yy < 0 || xx >= cols || yy >= rows) continue;
            sum += v[static_cast<size_t>(yy) * cols + xx];
            ++count;
          }
        out[static_cast<size_t>(y) * cols + x] = sum / static_cast<float>(count);
      }
    v.swap(out);
  }
  double sq = 0.0;
  for (float x : v) sq += static_cast<double>(x) * static_cast<double>(x);
  const float scale = sq > 0 ? static_cast<float>(1.0 / std::sqrt(sq / static_cast<double>(v.size()))) : 0.0f;
  for (float& x : v) x *= scale;
  return v;
}

}  // namespace

void compute_shade_maps(std::vector<SurfaceLook>& looks, const std::vector<Surface>& surfaces,
                        const std::vector<Light>& lights, const CollisionIndex& index,
                        const LightingOptions& options, uint64_t seed) {
  std::vector<std::vector<double>> direct(surfaces.size());
  double weighted = 0.0, area = 0.0;
  for (size_t i = 0; i < surfaces.size(); ++i) {
    const Surface& s = surfaces[i];
    ShadeMap& map = looks[i].shade;
    const double cell = std::max(options.cell_m, std::sqrt(s.area() / options.max_nodes));
    map.cols = static_cast<int>(std::ceil(s.width / cell)) + 1;
    map.rows = static_cast<int>(std::ceil(s.height / cell)) + 1;
    map.inv_cell = static_cast<float>(1.0 / cell);
    std::vector<double>& d = direct[i];
    d.resize(static_cast<size_t>(map.cols) * map.rows);
    double sum = 0.0;
    for (int y = 0; y < map.rows; ++y)
      for (int x = 0; x < map.cols; ++x) {
        const Eigen::Vector3d p = s.point(std::min(x * cell, s.width), std::min(y * cell, s.height)) + 0.01 * s.normal;
        const double e = lights.empty() ? 0.0 : direct_irradiance(p, s.normal, lights, index, options);
        d[static_cast<size_t>(y) * map.cols + x] = e;
        sum += e;
      }
    if (s.kind != SurfaceKind::kCeiling) {
      weighted += sum / static_cast<double>(d.size()) * s.area();
      area += s.area();
    }
  }
  const double mean = area > 0 ? weighted / area : 0.0;
  const double ambient = mean > 0 ? options.ambient : 1.0;
  const double gain = mean > 0 ? (1.0 - options.ambient) / mean : 0.0;
  for (size_t i = 0; i < surfaces.size(); ++i) {
    ShadeMap& map = looks[i].shade;
    Rng rng(derive(derive(seed, tag("shade")), static_cast<uint64_t>(surfaces[i].id)));
    const std::vector<float> slow = smooth_field(map.cols, map.rows, rng);
    map.values.resize(direct[i].size());
    for (size_t k = 0; k < map.values.size(); ++k) {
      const double e = ambient + gain * direct[i][k];
      map.values[k] = static_cast<float>(e * (1.0 + options.variation * static_cast<double>(slow[k])));
    }
  }
}

}  // namespace kestrel::sim
