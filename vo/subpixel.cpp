#include "vo/subpixel.h"

#include <Eigen/Cholesky>
#include <array>
#include <cmath>

namespace kestrel::vo {
namespace {

constexpr int kMaxWindow = 15;
constexpr int kMaxSide = kMaxWindow + 2;
using Patch = std::array<float, kMaxSide * kMaxSide>;

}  // namespace

SubpixelResult refine_subpixel(const cv::Mat& ref, const Eigen::Vector2i& ref_px, const cv::Mat& cur,
                               const Eigen::Vector2f& cur_start, int window, float max_shift,
                               int max_iterations) {
  SubpixelResult result;
  result.position = cur_start;
  if (window < 3 || window > kMaxWindow || window % 2 == 0) return result;
  const int r = window / 2;
  const int side = window + 2;  // one extra pixel on each side for central differences
  const int half = r + 1;
  if (ref_px.x() - half < 0 || ref_px.y() - half < 0 || ref_px.x() + half >= ref.cols ||
      ref_px.y() + half >= ref.rows)
    return result;

  Patch t{};
  for (int y = 0; y < side; ++y) {
    const uint8_t* row = ref.ptr<uint8_t>(ref_px.y() - half + y) + (ref_px.x() - half);
    for (int x = 0; x < side; ++x) t[static_cast<size_t>(y * side + x)] = row[x];
  }

  // The template's half of the gradients does not change between iterations.
  Patch tgx{}, tgy{};
  const size_t sd = static_cast<size_t>(side);
  for (int y = 1; y <= window; ++y) {
    for (int x = 1; x <= window; ++x) {
      const size_t i = static_cast<size_t>(y * side + x);
      tgx[i] = t[i + 1] - t[i - 1];
      tgy[i] = t[i + sd] - t[i - sd];
    }
  }

  Eigen::Vector2f pos = cur_start;
  float bias = 0.0f;
  Patch s{};
  for (int it = 0; it < max_iterations; ++it) {
    const float ox = pos.x() - float(half), oy = pos.y() - float(half);
    const int x0 = static_cast<int>(std::floor(ox)), y0 = static_cast<int>(std::floor(oy));
    if (x0 < 0 || y0 < 0 || x0 + side >= cur.cols || y0 + side >= cur.rows) return result;
    // Every sample shares the same fractional offset, hence the same bilinear weights.
    const float ax = ox - float(x0), ay = oy - float(y0);
    const float w00 = (1 - ax) * (1 - ay), w01 = ax * (1 - ay), w10 = (1 - ax) * ay, w11 = ax * ay;
    for (int y = 0; y < side; ++y) {
      const uint8_t* r0 = cur.ptr<uint8_t>(y0 + y) + x0;
      const uint8_t* r1 = cur.ptr<uint8_t>(y0 + y + 1) + x0;
      for (int x = 0; x < side; ++x)
        s[static_cast<size_t>(y * side + x)] = w00 * r0[x] + w01 * r0[x + 1] + w10 * r1[x] + w11 * r1[x + 1];
    }
    // The normal equations of J = (gx, gy, -1) accumulated as scalars: the compiler keeps
    // them in registers, where a generic rank update per pixel would not.
    float hxx = 0, hxy = 0, hyy = 0, sx = 0, sy = 0, ex = 0, ey = 0, se = 0, cost = 0;
    for (int y = 1; y <= window; ++y) {
      for (int x = 1; x <= window; ++x) {
        const size_t i = static_cast<size_t>(y * side + x);
        const float gx = 0.25f * (s[i + 1] - s[i - 1] + tgx[i]);
        const float gy = 0.25f * (s[i + sd] - s[i - sd] + tgy[i]);
        const float e = s[i] - t[i] - bias;
        hxx += gx * gx;
        hxy += gx * gy;
        hyy += gy * gy;
        sx += gx;
        sy += gy;
        ex += gx * e;
        ey += gy * e;
        se += e;
        cost += e * e;
      }
    }
    const float n = float(window * window);
    result.rms_error = std::sqrt(cost / n);
    Eigen::Matrix3f H;
    H << hxx, hxy, -sx, hxy, hyy, -sy, -sx, -sy, n;
    const Eigen::Vector3f g(ex, ey, -se);
    const Eigen::Vector3f delta = H.ldlt().solve(-g);
    if (!delta.allFinite()) return result;
    pos += delta.head<2>();
    bias += delta(2);
    result.iterations = it + 1;
    if ((pos - cur_start).norm() > max_shift) return result;
    if (delta.head<2>().squaredNorm() < 1e-4f) break;
  }
  result.position = pos;
  result.ok = true;
  return result;
}

}  // namespace kestrel::vo
