#include "drivers/sim/noise.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <stdexcept>

namespace kestrel::sim {
namespace {

// Catmull-Rom weights for the two fine samples that fall between coarse samples when the
// sampling rate doubles (offsets 0.75 and 0.25 of a coarse cell).
constexpr float kEven[4] = {-0.0234375f, 0.2265625f, 0.8671875f, -0.0703125f};
constexpr float kOdd[4] = {-0.0703125f, 0.8671875f, 0.2265625f, -0.0234375f};

bool is_power_of_two(int n) { return n > 0 && (n & (n - 1)) == 0; }

// Independent standard normal values, six per 64-bit draw through the normal table (exact
// Box-Muller for every texel would dominate texture generation).
cv::Mat random_cells(int cells, Rng& rng) {
  cv::Mat m(cells, cells, CV_32FC1);
  const NormalTable& table = normal_table();
  float* v = m.ptr<float>(0);
  const size_t n = static_cast<size_t>(cells) * cells;
  for (size_t i = 0; i < n; i += 6) {
    uint64_t bits = rng.next();
    for (size_t k = i; k < std::min(n, i + 6); ++k, bits >>= NormalTable::kBits)
      v[k] = table[static_cast<uint32_t>(bits)];
  }
  return m;
}

// Doubles the rows of a periodic field: fine row 2i lies 0.75 of the way from coarse row i-1
// to row i, fine row 2i+1 0.25 of the way from row i to row i+1 (cell-centred samples).
cv::Mat upsample_rows(const cv::Mat& in) {
  const int n = in.rows;
  cv::Mat out(2 * n, in.cols, CV_32FC1);
  for (int i = 0; i < n; ++i) {
    const float* r[4];
    for (int k = 0; k < 4; ++k) r[k] = in.ptr<float>(((i + k - 2) % n + n) % n);
    const float* s[4];
    for (int k = 0; k < 4; ++k) s[k] = in.ptr<float>(((i + k - 1) % n + n) % n);
    float* even = out.ptr<float>(2 * i);
    float* odd = out.ptr<float>(2 * i + 1);
    for (int c = 0; c < in.cols; ++c) {
      even[c] = kEven[0] * r[0][c] + kEven[1] * r[1][c] + kEven[2] * r[2][c] + kEven[3] * r[3][c];
      odd[c] = kOdd[0] * s[0][c] + kOdd[1] * s[1][c] + kOdd[2] * s[2][c] + kOdd[3] * s[3][c];
    }
  }
  return out;
}

// Doubles the columns of a periodic field, with the same weights as upsample_rows.
cv::Mat upsample_cols(const cv::Mat& in) {
  const int n = in.cols;
  cv::Mat out(in.rows, 2 * n, CV_32FC1);
  for (int r = 0; r < in.rows; ++r) {
    const float* src = in.ptr<float>(r);
    float* dst = out.ptr<float>(r);
    for (int i = 0; i < n; ++i) {
      const float a = src[(i + n - 2) % n], b = src[(i + n - 1) % n], c = src[i], d = src[(i + 1) % n],
                  e = src[(i + 2) % n];
      dst[2 * i] = kEven[0] * a + kEven[1] * b + kEven[2] * c + kEven[3] * d;
      dst[2 * i + 1] = kOdd[0] * b + kOdd[1] * c + kOdd[2] * d + kOdd[3] * e;
    }
  }
  return out;
}

}  // namespace

cv::Mat upsample2_periodic(const cv::Mat& field) {
  CV_Assert(field.type() == CV_32FC1 && field.rows == field.cols);
  return upsample_rows(upsample_cols(field));
}

void standardize(cv::Mat& field) {
  cv::Scalar mean, stddev;
  cv::meanStdDev(field, mean, stddev);
  const double s = stddev[0] > 1e-12 ? 1.0 / stddev[0] : 0.0;
  field.convertTo(field, CV_32FC1, s, -mean[0] * s);
}

cv::Mat fractal_noise(int size, int coarse_cells, int fine_cells, double gain, Rng& rng) {
  if (!is_power_of_two(size) || !is_power_of_two(coarse_cells) || !is_power_of_two(fine_cells) ||
      coarse_cells > fine_cells || fine_cells > size) {
    throw std::invalid_argument("fractal_noise: sizes must be powers of two, coarse <= fine <= size");
  }
  cv::Mat field = random_cells(coarse_cells, rng);
  double amplitude = 1.0;
  while (field.rows < size) {
    field = upsample2_periodic(field);
    if (field.rows <= fine_cells) {
      amplitude *= gain;
      field += random_cells(field.rows, rng) * amplitude;
    }
  }
  standardize(field);
  return field;
}

cv::Mat smooth_noise(int size, int cells, Rng& rng) {
  return fractal_noise(size, cells, cells, 0.0, rng);
}

}  // namespace kestrel::sim
