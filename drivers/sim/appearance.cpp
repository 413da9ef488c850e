#include "drivers/sim/appearance.h"

#include <opencv2/features2d.hpp>

#include <cmath>
#include <map>

#include "common/numbers.h"
#include "drivers/sim/noise.h"
#include "drivers/sim/random.h"

namespace kestrel::sim {
namespace {

// Relative amplitude of the wear layer on tiled and on fitted materials.
constexpr float kWearGainTiled = 0.10f;
constexpr float kWearGainFitted = 0.03f;

}  // namespace

std::shared_ptr<const MipTexture> make_wear_texture(uint64_t seed) {
  Rng rng(derive(seed, tag("wear")));
  const cv::Mat n = fractal_noise(kWearSize, 8, kWearSize, 0.6, rng);
  cv::Mat rgb(kWearSize, kWearSize, CV_32FC3);
  for (int r = 0; r < kWearSize; ++r) {
    const float* in = n.ptr<float>(r);
    cv::Vec3f* out = rgb.ptr<cv::Vec3f>(r);
    for (int c = 0; c < kWearSize; ++c) {
      const float g = 0.5f + 0.15f * in[c];
      out[c] = cv::Vec3f(g, g, g);
    }
  }
  auto wear = std::make_shared<MipTexture>(rgb);
  wear->add_grey_levels();  // the renderer reads it with grey_span
  return wear;
}

std::vector<SurfaceLook> make_looks(const std::vector<Surface>& surfaces,
                                    const std::vector<MaterialSpec>& materials, uint64_t seed) {
  std::map<int, std::shared_ptr<const MipTexture>> tiled;
  std::vector<SurfaceLook> looks(surfaces.size());
  for (size_t i = 0; i < surfaces.size(); ++i) {
    const Surface& s = surfaces[i];
    const MaterialSpec& spec = materials.at(static_cast<size_t>(s.material));
    const uint64_t material_seed = derive(seed, tag(spec.name));
    Rng rng(derive(derive(seed, tag("surface")), static_cast<uint64_t>(s.id)));
    SurfaceLook& look = looks[i];
    if (spec.fit) {
      look.texture = make_texture(spec, derive(material_seed, static_cast<uint64_t>(s.id)));
      const int size = look.texture->size();
      look.texels_per_m_s = static_cast<float>(size / std::max(s.width, 1e-3));
      look.texels_per_m_t = static_cast<float>(size / std::max(s.height, 1e-3));
      look.wear_gain = kWearGainFitted;
    } else {
      auto& shared = tiled[s.material];
      if (!shared) shared = make_texture(spec, material_seed);
      look.texture = shared;
      const int size = look.texture->size();
      const float tpm = static_cast<float>(size / pattern_period_m(spec));
      look.texels_per_m_s = look.texels_per_m_t = tpm;
      look.offset_s = static_cast<float>(rng.uniform(0, size));
      look.offset_t = static_cast<float>(rng.uniform(0, size));
      look.wear_gain = kWearGainTiled;
    }
    look.detail = static_cast<float>(s.texture);
    look.mean = look.texture->mean() * 255.0f;
    const double angle = rng.uniform(0, kTwoPi);
    const float k = static_cast<float>(1.0 / kWearTexelM);
    look.wear_m[0] = k * static_cast<float>(std::cos(angle));
    look.wear_m[1] = -k * static_cast<float>(std::sin(angle));
    look.wear_m[2] = k * static_cast<float>(std::sin(angle));
    look.wear_m[3] = k * static_cast<float>(std::cos(angle));
    look.wear_offset[0] = static_cast<float>(rng.uniform(0, kWearSize));
    look.wear_offset[1] = static_cast<float>(rng.uniform(0, kWearSize));
  }
  return looks;
}

double measure_feature_density(const SurfaceLook& look) {
  const MipTexture& tex = *look.texture;
  const double footprint_m = 2.0 / 525.0;
  const double texels = footprint_m * std::sqrt(static_cast<double>(look.texels_per_m_s) * static_cast<double>(look.texels_per_m_t));
  const int level = std::clamp(static_cast<int>(std::lround(std::log2(std::max(texels, 1.0)))), 0, tex.levels() - 1);
  const int n = tex.size() >> level;
  if (n < 16) return 0.0;
  cv::Mat grey(n, n, CV_8UC1);
  const std::vector<uint32_t>& data = tex.level(level);
  for (int r = 0; r < n; ++r) {
    uchar* o = grey.ptr<uchar>(r);
    for (int c = 0; c < n; ++c) {
      const uint32_t t = data[static_cast<size_t>(r) * n + c];
      float g = 0.0f;
      const float w[3] = {0.299f, 0.587f, 0.114f};
      for (int ch = 0; ch < 3; ++ch) {
        const float v = static_cast<float>((t >> (8 * ch)) & 255u);
        g += w[ch] * (look.mean[ch] + look.detail * (v - look.mean[ch]));
      }
      o[c] = cv::saturate_cast<uchar>(g);
    }
  }
  std::vector<cv::KeyPoint> corners;
  cv::FAST(grey, corners, 20, true);
  const double area_m2 = (tex.size() / static_cast<double>(look.texels_per_m_s)) *
                         (tex.size() / static_cast<double>(look.texels_per_m_t));
  return static_cast<double>(corners.size()) / area_m2;
}

}  // namespace kestrel::sim
