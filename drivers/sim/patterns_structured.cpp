// Structured surfaces: brick, wooden planks, floor and ceiling tiles, book shelves. Every
// layout fits a whole number of its units into the tile, so the tile stays periodic.

#include <algorithm>
#include <cmath>
#include <vector>

#include "common/numbers.h"
#include "drivers/sim/noise.h"
#include "drivers/sim/patterns.h"

namespace kestrel::sim::patterns {
namespace {

cv::Vec3f vec(const Eigen::Vector3d& c) {
  return {static_cast<float>(c.x()), static_cast<float>(c.y()), static_cast<float>(c.z())};
}

// A colour near `base`: brightness and hue jittered by up to `amount` (relative).
cv::Vec3f jitter(const cv::Vec3f& base, double amount, uint64_t key, int64_t i, int64_t j) {
  const float b = static_cast<float>(1.0 + amount * (2.0 * cell_random(key, i, j) - 1.0));
  cv::Vec3f out = base * b;
  for (int c = 0; c < 3; ++c)
    out[c] *= static_cast<float>(1.0 + 0.3 * amount * (2.0 * cell_random(key + 1 + c, i, j) - 1.0));
  return out;
}

}  // namespace

// Running-bond brick: 9 bricks by 28 courses per tile, mortar joints, per-brick tone, worn
// edges and surface grain.
cv::Mat brick(const MaterialSpec& spec, int size, Rng& rng) {
  const float k = static_cast<float>(spec.contrast);
  const int per_row = 9, rows = 28;
  const double bw = static_cast<double>(size) / per_row, bh = static_cast<double>(size) / rows;
  const double mortar = 0.13 * bh;  // about 1 cm at the default scale
  const cv::Mat grain = fractal_noise(size, 16, size, 0.65, rng);
  const uint64_t key = rng.next();
  const cv::Vec3f base = vec(spec.color);
  const cv::Vec3f mortar_color(0.62f, 0.60f, 0.56f);
  cv::Mat rgb(size, size, CV_32FC3);
  std::vector<cv::Vec3f> tones(static_cast<size_t>(per_row) * rows);
  for (int i = 0; i < rows; ++i)
    for (int j = 0; j < per_row; ++j) tones[static_cast<size_t>(i) * per_row + j] = jitter(base, 0.14 * spec.contrast, key, i, j);
  for (int r = 0; r < size; ++r) {
    const double y = r + 0.5;
    const int course = std::min(rows - 1, static_cast<int>(y / bh));
    const double ly = y - course * bh;
    const double shift = (course % 2) ? bw / 2 : 0.0;
    const float* g = grain.ptr<float>(r);
    cv::Vec3f* o = rgb.ptr<cv::Vec3f>(r);
    for (int c = 0; c < size; ++c) {
      const double x = std::fmod(c + 0.5 + shift, static_cast<double>(size));
      const int col = std::min(per_row - 1, static_cast<int>(x / bw));
      const double lx = x - col * bw;
      if (std::min(lx, ly) < mortar) {
        o[c] = mortar_color * (1.0f + 0.12f * k * g[c]);
        continue;
      }
      const cv::Vec3f& tone = tones[static_cast<size_t>(course) * per_row + col];
      const double edge = std::min({lx - mortar, bw - lx, ly - mortar, bh - ly});
      const float wear = edge < 2.0 ? 0.85f : 1.0f;
      o[c] = tone * (wear * (1.0f + 0.09f * k * g[c]));
    }
  }
  return rgb;
}

// Wooden planks running along s: 12 boards per tile, joints at random places, grain lines a
// few millimetres apart, warped by smooth noise.
cv::Mat wood(const MaterialSpec& spec, int size, Rng& rng) {
  const float k = static_cast<float>(spec.contrast);
  const int boards = 12;
  const double bh = static_cast<double>(size) / boards;
  const cv::Mat warp = fractal_noise(size, 4, 64, 0.5, rng);
  const cv::Mat fine = fractal_noise(size, size / 4, size, 0.7, rng);
  const uint64_t key = rng.next();
  const double grain_cycles = std::round(size / 6.0);  // a grain line every ~6 texels
  const cv::Vec3f base = vec(spec.color);
  cv::Mat rgb(size, size, CV_32FC3);
  for (int r = 0; r < size; ++r) {
    const int board = static_cast<int>((r + 0.5) / bh);
    const double ly = r + 0.5 - board * bh;
    const double joint = cell_random(key, board, 0) * size;  // one butt joint per board per tile
    const cv::Vec3f tone = jitter(base, 0.12 * spec.contrast, key, board, 1);
    const double board_phase = cell_random(key, board, 2);
    const float* w = warp.ptr<float>(r);
    const float* f = fine.ptr<float>(r);
    cv::Vec3f* o = rgb.ptr<cv::Vec3f>(r);
    for (int c = 0; c < size; ++c) {
      const double dj = std::abs(c + 0.5 - joint);
      const bool seam = ly < 1.0 || std::min(dj, size - dj) < 1.0;
      const double phase = grain_cycles * (r + 0.5) / size + 1.5 * static_cast<double>(w[c]) + board_phase;
      const float grain = static_cast<float>(std::sin(kTwoPi * phase));
      const float lum = 1.0f + k * (0.10f * grain * grain - 0.05f + 0.05f * f[c]);
      o[c] = seam ? tone * 0.55f : tone * lum;
    }
  }
  return rgb;
}

// Floor tiles: 8 x 8 tiles per tile period with grout joints; terrazzo-like speckle.
cv::Mat floor_tiles(const MaterialSpec& spec, int size, Rng& rng) {
  const float k = static_cast<float>(spec.contrast);
  const double pitch = size / 8.0;
  const double grout = 0.014 * pitch;
  const cv::Mat speck = fractal_noise(size, size / 4, size, 0.85, rng);
  const cv::Mat cloud = fractal_noise(size, 8, size / 4, 0.6, rng);
  const uint64_t key = rng.next();
  const cv::Vec3f base = vec(spec.color);
  cv::Vec3f tones[8][8];
  for (int i = 0; i < 8; ++i)
    for (int j = 0; j < 8; ++j) tones[i][j] = jitter(base, 0.06 * spec.contrast, key, i, j);
  cv::Mat rgb(size, size, CV_32FC3);
  for (int r = 0; r < size; ++r) {
    const int ty = std::min(7, static_cast<int>((r + 0.5) / pitch));
    const double ly = r + 0.5 - ty * pitch;
    const float* s = speck.ptr<float>(r);
    const float* cl = cloud.ptr<float>(r);
    cv::Vec3f* o = rgb.ptr<cv::Vec3f>(r);
    for (int c = 0; c < size; ++c) {
      const int tx = std::min(7, static_cast<int>((c + 0.5) / pitch));
      const double lx = c + 0.5 - tx * pitch;
      if (std::min(lx, ly) < grout * 2.5) {
        o[c] = base * 0.55f;
        continue;
      }
      const cv::Vec3f& tone = tones[ty][tx];
      const float dot = s[c] > 1.9f ? 0.6f : (s[c] < -2.1f ? 1.25f : 1.0f);
      o[c] = tone * (dot * (1.0f + k * (0.06f * cl[c] + 0.03f * s[c])));
    }
  }
  return rgb;
}

// Suspended ceiling: 4 x 4 fissured mineral tiles per period on a light metal grid.
cv::Mat ceiling_tiles(const MaterialSpec& spec, int size, Rng& rng) {
  const float k = static_cast<float>(spec.contrast);
  const double pitch = size / 4.0;
  const double bar = 0.04 * pitch;
  const cv::Mat fissure = fractal_noise(size, size / 8, size / 2, 0.9, rng);
  const cv::Mat soft = fractal_noise(size, 4, size / 8, 0.6, rng);
  const cv::Vec3f base = vec(spec.color);
  cv::Mat rgb(size, size, CV_32FC3);
  for (int r = 0; r < size; ++r) {
    const double ly = std::fmod(r + 0.5, pitch);
    const float* f = fissure.ptr<float>(r);
    const float* s = soft.ptr<float>(r);
    cv::Vec3f* o = rgb.ptr<cv::Vec3f>(r);
    for (int c = 0; c < size; ++c) {
      const double lx = std::fmod(c + 0.5, pitch);
      const double d = std::min({lx, pitch - lx, ly, pitch - ly});
      if (d < bar / 2) {
        o[c] = cv::Vec3f(0.8f, 0.8f, 0.78f);
        continue;
      }
      const float shade = d < bar ? 0.8f : 1.0f;  // the tile edge sits in shadow of the grid
      const float hole = f[c] > 1.8f ? 1.0f - 0.35f * k : 1.0f;
      o[c] = base * (shade * hole * (1.0f + 0.04f * k * s[c]));
    }
  }
  return rgb;
}

// Book shelves: 6 shelves per period, books of random width, height and colour with title
// bands on their spines, dark gaps above them.
cv::Mat books(const MaterialSpec& spec, int size, Rng& rng) {
  const float k = static_cast<float>(spec.contrast);
  const int shelves = 6;
  const double shelf_h = static_cast<double>(size) / shelves;
  const double board = 0.06 * shelf_h;
  const cv::Mat grain = fractal_noise(size, 16, size, 0.7, rng);
  cv::Mat rgb(size, size, CV_32FC3, cv::Scalar(0.12, 0.1, 0.09));
  const cv::Vec3f board_color = vec(spec.color);
  for (int s = 0; s < shelves; ++s) {
    const int y0 = static_cast<int>(s * shelf_h);
    const int y1 = static_cast<int>((s + 1) * shelf_h);
    const int yb = y0 + static_cast<int>(board);
    rgb.rowRange(y0, yb).setTo(cv::Scalar(static_cast<double>(board_color[0]),
                                          static_cast<double>(board_color[1]),
                                          static_cast<double>(board_color[2])));
    // Books fill [0, size) exactly: the last one takes what is left.
    int x = 0;
    while (x < size) {
      int w = std::max(4, static_cast<int>(rng.uniform(0.006, 0.025) * size));
      if (size - x < w + 4) w = size - x;
      const double height = rng.uniform(0.55, 0.92) * (shelf_h - board);
      const cv::Vec3f color(static_cast<float>(rng.uniform(0.1, 0.85)),
                            static_cast<float>(rng.uniform(0.1, 0.8)),
                            static_cast<float>(rng.uniform(0.1, 0.75)));
      const double band_at = rng.uniform(0.5, 0.8) * height;
      const double band_h = rng.uniform(0.05, 0.15) * height;
      const cv::Vec3f band = rng.uniform() < 0.5 ? cv::Vec3f(0.9f, 0.85f, 0.6f) : color * 0.4f;
      for (int yy = yb; yy < std::min(y1, yb + static_cast<int>(height)); ++yy) {
        const double ly = yy - yb;
        const float* g = grain.ptr<float>(yy);
        cv::Vec3f* o = rgb.ptr<cv::Vec3f>(yy);
        for (int xx = x; xx < x + w; ++xx) {
          const bool gap = xx == x;  // a dark line between books
          const bool in_band = ly > band_at && ly < band_at + band_h;
          const cv::Vec3f c = in_band ? band : color;
          o[xx] = gap ? c * 0.3f : c * (1.0f + 0.05f * k * g[xx]);
        }
      }
      x += w;
    }
  }
  return rgb;
}

}  // namespace kestrel::sim::patterns
