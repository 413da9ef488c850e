#include "drivers/sim/renderer.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <type_traits>

#include "drivers/sim/kinect_depth.h"
#include "drivers/sim/random.h"
#include "drivers/sim/rgb_sensor.h"

namespace kestrel::sim {
namespace {

// log2 to about 0.01: exponent bits plus a quadratic in the mantissa. Only chooses mip levels.
inline float fast_log2(float x) {
  uint32_t bits;
  std::memcpy(&bits, &x, sizeof bits);
  const float exponent = static_cast<float>(static_cast<int>(bits >> 23) - 127);
  bits = (bits & 0x007fffffu) | 0x3f800000u;
  float m;
  std::memcpy(&m, &bits, sizeof m);
  const float f = m - 1.0f;
  return exponent + f * (1.3465557f - 0.34655573f * f);
}

// Pixels per shading chunk, and the largest error of a chunk's linear light, relative (1e-3:
// about a tenth of a grey level); see Renderer::shade.
constexpr int kChunk = 16;
constexpr float kMaxLightError = 1e-3f;

// What a pixel of one visible surface needs, hoisted out of the pixel loop.
struct Shader {
  const MipTexture* texture;
  const ShadeMap* shade;
  float tex_s, tex_t, off_s, off_t;  // texels per metre and offsets
  float lod_c, wear_lod_c;           // lod = 1.5 log2 z + lod_c
  float detail;
  float base[3];                     // mean * (1 - detail)
  float ir_base;                     // its luma
  float wear_k;                      // wear_gain * detail / 38.25 (a unit normal per 38.25 grey)
  float wear_m[4], wear_o[2];
  float abs_d;                       // |plane_d|, for the incidence angle
};

}  // namespace

Renderer::Renderer(const World& world, const CameraOptions& options, uint64_t seed)
    : world_(world), options_(options), seed_(seed), raster_(options.camera, options.near_m, options.far_m) {
  options_.camera.validate("sim camera");
  if (options_.rgb.motion_blur_samples < 1) throw std::invalid_argument("motion_blur_samples must be >= 1");
  const PinholeCamera& c = options_.camera;
  const size_t n = static_cast<size_t>(c.width) * c.height;
  for (auto& p : planes_) p.assign(n, 0.0f);
  ir_return_.assign(n, 0.0f);
  ray_inverse_norm_.resize(n);
  for (int v = 0; v < c.height; ++v)
    for (int u = 0; u < c.width; ++u) {
      const double x = (u - c.cx) / c.fx, y = (v - c.cy) / c.fy;
      ray_inverse_norm_[static_cast<size_t>(v) * c.width + u] = static_cast<float>(1.0 / std::sqrt(x * x + y * y + 1.0));
    }
}

RgbdFrame Renderer::render(const Eigen::Isometry3d& T_world_camera, int64_t utime, int64_t seq) {
  return render(std::vector<Eigen::Isometry3d>{T_world_camera}, utime, seq);
}

RgbdFrame Renderer::render(const std::vector<Eigen::Isometry3d>& exposure, int64_t utime, int64_t seq) {
  if (exposure.empty()) throw std::invalid_argument("Renderer::render: no pose");
  const size_t middle = exposure.size() / 2;
  // With one pose the planes are written, not accumulated (no clearing pass).
  const bool accumulate = exposure.size() > 1;
  if (accumulate)
    for (auto& p : planes_) std::fill(p.begin(), p.end(), 0.0f);
  // The middle pose last, so the rasteriser's buffers hold it for the depth image.
  for (size_t i = 0; i < exposure.size(); ++i) {
    if (i == middle) continue;
    raster_.draw(world_.surfaces(), exposure[i]);
    shade(false, true);
  }
  raster_.draw(world_.surfaces(), exposure[middle]);
  shade(true, accumulate);
  if (exposure.size() > 1) {
    const float scale = 1.0f / static_cast<float>(exposure.size());
    for (auto& p : planes_)
      for (float& x : p) x *= scale;
  }
  const uint64_t frame_key = derive(derive(seed_, tag("camera")), static_cast<uint64_t>(seq));
  RgbdFrame frame;
  frame.utime = utime;
  frame.depth_utime = utime;
  frame.seq = seq;
  frame.camera = options_.camera;
  frame.sensor = sensor_model::kSimulator;
  frame.T_body_camera = options_.T_body_camera;
  expose_rgb(planes_, options_.camera, options_.rgb, static_cast<uint32_t>(frame_key), frame.rgb);
  make_kinect_depth(raster_, ir_return_, options_.depth, static_cast<uint32_t>(frame_key >> 32), frame.depth_mm);
  return frame;
}

void Renderer::shade(bool ir, bool accumulate) {
  const PinholeCamera& cam = options_.camera;
  const auto& visible = raster_.visible();
  const float f = static_cast<float>(0.5 * (cam.fx + cam.fy));
  const float exposure = static_cast<float>(options_.rgb.exposure);
  std::vector<Shader> shaders(visible.size());
  for (size_t i = 0; i < visible.size(); ++i) {
    const SurfaceLook& look = world_.look(visible[i].surface);
    Shader& s = shaders[i];
    s.texture = look.texture.get();
    s.shade = &look.shade;
    s.tex_s = look.texels_per_m_s;
    s.tex_t = look.texels_per_m_t;
    s.off_s = look.offset_s;
    s.off_t = look.offset_t;
    s.abs_d = std::abs(visible[i].plane_d);
    // Footprint of a pixel on the plane, geometric mean of its two axes: z^1.5 / (f sqrt|d|).
    const float base = -std::log2(f) - 0.5f * std::log2(std::max(s.abs_d, 1e-6f));
    s.lod_c = base + 0.5f * std::log2(look.texels_per_m_s * look.texels_per_m_t);
    s.wear_lod_c = base - static_cast<float>(std::log2(kWearTexelM));
    s.detail = look.detail;
    // albedo = mean + detail (texel - mean) = base + detail texel
    for (int c = 0; c < 3; ++c) s.base[c] = look.mean[c] * (1.0f - look.detail);
    s.ir_base = 0.299f * s.base[0] + 0.587f * s.base[1] + 0.114f * s.base[2];
    s.wear_k = look.wear_gain * look.detail / 38.25f;
    std::copy(look.wear_m, look.wear_m + 4, s.wear_m);
    std::copy(look.wear_offset, look.wear_offset + 2, s.wear_o);
  }
  const MipTexture& wear = world_.wear_texture();
  if (!wear.has_grey_levels()) throw std::logic_error("Renderer: the wear texture needs its grey levels");
  const int w = cam.width;
  const int wear_top = wear.levels() - 1;
  uint32_t texels[kChunk], texels_next[kChunk], greys[kChunk];
  float lights[kChunk];
  for (int v = 0; v < cam.height; ++v) {
    const uint16_t* ids = raster_.ids(v);
    const float* inv = raster_.inverse_depth(v);
    const size_t row = static_cast<size_t>(v) * w;
    float* R = planes_[0].data() + row;
    float* G = planes_[1].data() + row;
    float* B = planes_[2].data() + row;
    float* irow = ir_return_.data() + row;
    const float* rin = ray_inverse_norm_.data() + row;
    const float fv = static_cast<float>(v);
    for (int u = 0; u < w;) {
      const uint16_t id = ids[u];
      int end = u + 1;
      while (end < w && ids[end] == id) ++end;
      if (id == Rasterizer::kNone) {
        if (ir) std::fill(irow + u, irow + end, 0.0f);
        if (!accumulate) {
          std::fill(R + u, R + end, 0.0f);
          std::fill(G + u, G + end, 0.0f);
          std::fill(B + u, B + end, 0.0f);
        }
        u = end;
        continue;
      }
      const ViewSurface& vs = visible[id];
      const Shader& s = shaders[id];
      const float s_row = vs.s_b * fv + vs.s_c, t_row = vs.t_b * fv + vs.t_c;
      auto surface_point = [&](int x, float& sm, float& tm) {
        const float z = 1.0f / inv[x];
        sm = z * (vs.s_a * static_cast<float>(x) + s_row) + vs.s_0;
        tm = z * (vs.t_a * static_cast<float>(x) + t_row) + vs.t_0;
      };
      // Chunks of up to kChunk pixels: exact (perspective) surface coordinates at the first
      // and last pixel, linear in between; one mip level (or one blend) per chunk. A chunk is
      // fixed in the image while the surface moves, so whatever its linear steps get wrong
      // moves with the camera, and the VO reads it as motion
      // (docs/decisions/2026-12-06-stata-flights-rotation-drift.md, where both were measured):
      // - Light. A line over the chunk cuts off the light map's shadow edges and lamp pools.
      //   Always linear (this renderer until 2026-12-06), it was most of the VO's rotation
      //   drift in stata's corridor: 2.00° in 18 s on exact images, 0.87° with the rule below.
      // - Surface coordinates, off by (w1-w0)/(2(w0+w1)) of the chunk's extent at its middle,
      //   w the inverse depth: a small fraction of a texel face on, several texels on a wall
      //   at a grazing angle. Shorter chunks there (under 1/8 texel) changed that drift by less
      //   than a run's spread and cost floor's frames a few ms, so the chunks stay 16 px.
      // A chunk's work; full chunks (the common case) with a compile-time count, so their
      // loops need no remainder handling.
      auto chunk = [&](auto count) {
        const int n = count;
        float s0, t0, s1, t1;
        surface_point(u, s0, t0);
        surface_point(u + n - 1, s1, t1);
        const float step = n > 1 ? 1.0f / static_cast<float>(n - 1) : 0.0f;
        const float lz = 1.5f * fast_log2(2.0f / (inv[u] + inv[u + n - 1]));
        // Material texture, brilinear as MipTexture::sample, at the chunk's level.
        const float x0 = s0 * s.tex_s + s.off_s, y0 = t0 * s.tex_t + s.off_t;
        const float dx = (s1 - s0) * s.tex_s * step, dy = (t1 - t0) * s.tex_t * step;
        const MipTexture& tex = *s.texture;
        const float lod = std::clamp(lz + s.lod_c, 0.0f, static_cast<float>(tex.levels() - 1));
        int level = static_cast<int>(lod);
        const float frac = lod - static_cast<float>(level);
        uint32_t blend = 0;
        if (level + 1 < tex.levels()) {
          if (frac > 0.75f) ++level;
          else if (frac >= 0.25f) blend = static_cast<uint32_t>((frac - 0.25f) * 512.0f);
        }
        tex.bilinear_span(level, tex.fixed_coordinate(level, x0), tex.fixed_coordinate(level, y0),
                          tex.fixed_step(level, dx), tex.fixed_step(level, dy), n, texels);
        if (blend > 0) {
          tex.bilinear_span(level + 1, tex.fixed_coordinate(level + 1, x0), tex.fixed_coordinate(level + 1, y0),
                            tex.fixed_step(level + 1, dx), tex.fixed_step(level + 1, dy), n, texels_next);
          for (int i = 0; i < n; ++i) texels[i] = MipTexture::lerp(texels[i], texels_next[i], blend);
        }
        // Wear layer: nearest level.
        const float wx0 = s.wear_m[0] * s0 + s.wear_m[1] * t0 + s.wear_o[0];
        const float wy0 = s.wear_m[2] * s0 + s.wear_m[3] * t0 + s.wear_o[1];
        const float wdx = (s.wear_m[0] * (s1 - s0) + s.wear_m[1] * (t1 - t0)) * step;
        const float wdy = (s.wear_m[2] * (s1 - s0) + s.wear_m[3] * (t1 - t0)) * step;
        const int wl = std::clamp(static_cast<int>(lz + s.wear_lod_c + 0.5f), 0, wear_top);
        wear.grey_span(wl, wear.fixed_coordinate(wl, wx0), wear.fixed_coordinate(wl, wy0),
                           wear.fixed_step(wl, wdx), wear.fixed_step(wl, wdy), n, greys);
        // Light: linear over the chunk where the light map is (its middle within
        // kMaxLightError of the line), else at every pixel. The map is bilinear between nodes;
        // a chunk spans one node line at most in all but the farthest views, and then the
        // error at the middle is at least half the largest.
        const float light0 = s.shade->at(s0, t0) * exposure;
        const float light1 = s.shade->at(s1, t1) * exposure;
        const float light_mid = s.shade->at(0.5f * (s0 + s1), 0.5f * (t0 + t1)) * exposure;
        if (std::abs(light_mid - 0.5f * (light0 + light1)) <= kMaxLightError * std::max(light0, light1)) {
          const float dlight = (light1 - light0) * step;
          for (int i = 0; i < n; ++i) lights[i] = light0 + dlight * static_cast<float>(i);
        } else {
          const float ds = (s1 - s0) * step, dt = (t1 - t0) * step;
          for (int i = 0; i < n; ++i)
            lights[i] = s.shade->at(s0 + ds * static_cast<float>(i), t0 + dt * static_cast<float>(i)) * exposure;
        }
        float* r = R + u;
        float* g = G + u;
        float* b = B + u;
        // Written, or added to what earlier poses left (the same values when that is 0).
        auto radiance = [&](auto add) {
          for (int i = 0; i < n; ++i) {
            const uint32_t texel = texels[i];
            const float wear_factor = 1.0f + s.wear_k * (static_cast<float>(greys[i] & 255u) - 127.5f);
            const float light = lights[i] * wear_factor;
            const float vr = (s.base[0] + s.detail * static_cast<float>(texel & 255u)) * light;
            const float vg = (s.base[1] + s.detail * static_cast<float>((texel >> 8) & 255u)) * light;
            const float vb = (s.base[2] + s.detail * static_cast<float>((texel >> 16) & 255u)) * light;
            if constexpr (decltype(add)::value) {
              r[i] += vr, g[i] += vg, b[i] += vb;
            } else {
              r[i] = vr, g[i] = vg, b[i] = vb;
            }
          }
        };
        if (accumulate) radiance(std::true_type{});
        else radiance(std::false_type{});
        if (ir) {
          const float* iz = inv + u;
          const float* rn = rin + u;
          float* out = irow + u;
          for (int i = 0; i < n; ++i) {
            const uint32_t texel = texels[i];
            const float wear_factor = 1.0f + s.wear_k * (static_cast<float>(greys[i] & 255u) - 127.5f);
            const float grey = s.ir_base + s.detail * (0.299f * static_cast<float>(texel & 255u) +
                                                       0.587f * static_cast<float>((texel >> 8) & 255u) +
                                                       0.114f * static_cast<float>((texel >> 16) & 255u));
            out[i] = grey * wear_factor * (1.0f / 255.0f) * iz[i] * s.abs_d * rn[i];
          }
        }
      };
      for (; u < end; u += kChunk) {
        if (end - u >= kChunk) chunk(std::integral_constant<int, kChunk>{});
        else chunk(end - u);
      }
      u = end;
    }
  }
}

cv::Mat Renderer::ideal_depth() const {
  const PinholeCamera& cam = options_.camera;
  cv::Mat depth(cam.height, cam.width, CV_32FC1);
  for (int v = 0; v < cam.height; ++v) {
    const float* inv = raster_.inverse_depth(v);
    float* out = depth.ptr<float>(v);
    for (int u = 0; u < cam.width; ++u) out[u] = inv[u] > 0.0f ? 1.0f / inv[u] : 0.0f;
  }
  return depth;
}

cv::Mat Renderer::surface_ids() const {
  const PinholeCamera& cam = options_.camera;
  cv::Mat ids(cam.height, cam.width, CV_32SC1);
  for (int v = 0; v < cam.height; ++v) {
    const uint16_t* in = raster_.ids(v);
    int* out = ids.ptr<int>(v);
    for (int u = 0; u < cam.width; ++u)
      out[u] = in[u] == Rasterizer::kNone ? -1 : raster_.visible()[in[u]].surface;
  }
  return ids;
}

}  // namespace kestrel::sim
