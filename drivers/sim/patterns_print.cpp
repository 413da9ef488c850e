// Printed and written surfaces: posters (photographs, headings, columns of text, logos) and
// whiteboards (marker strokes on faint ghosting). Both are fitted: one instance per surface,
// with a plain margin so that the wrap-around of the lookup at the panel edge is invisible.

#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>

#include "drivers/sim/noise.h"
#include "drivers/sim/patterns.h"

namespace kestrel::sim::patterns {
namespace {

cv::Scalar random_color(Rng& rng, double lo, double hi) {
  return cv::Scalar(rng.uniform(lo, hi) * 255, rng.uniform(lo, hi) * 255, rng.uniform(lo, hi) * 255);
}

// A "photograph": three correlated fractal fields around a random colour, with a few objects.
void draw_photo(cv::Mat& img, const cv::Rect& box, Rng& rng) {
  const int n = img.rows;
  const cv::Mat base = fractal_noise(n, 4, n / 2, 0.55, rng);
  cv::Mat tint[3];
  for (auto& t : tint) t = fractal_noise(n, 2, 32, 0.5, rng);
  const cv::Vec3d mean(rng.uniform(0.25, 0.75), rng.uniform(0.25, 0.75), rng.uniform(0.25, 0.75));
  for (int r = box.y; r < box.y + box.height; ++r) {
    cv::Vec3b* o = img.ptr<cv::Vec3b>(r);
    const float* b = base.ptr<float>(r);
    for (int c = box.x; c < box.x + box.width; ++c) {
      for (int ch = 0; ch < 3; ++ch) {
        const double v = mean[ch] + 0.16 * static_cast<double>(b[c]) + 0.08 * static_cast<double>(tint[ch].at<float>(r, c));
        o[c][ch] = cv::saturate_cast<uchar>(255.0 * v);
      }
    }
  }
  const int objects = 1 + rng.below(4);
  for (int i = 0; i < objects; ++i) {
    const cv::Point centre(box.x + rng.below(std::max(1, box.width)), box.y + rng.below(std::max(1, box.height)));
    const cv::Size axes(2 + rng.below(std::max(1, box.width / 4)), 2 + rng.below(std::max(1, box.height / 4)));
    cv::ellipse(img(box), centre - box.tl(), axes, rng.uniform(0, 180), 0, 360,
                random_color(rng, 0.05, 0.95), cv::FILLED, cv::LINE_AA);
  }
}

// Lines of "words": dark dashes of random length, `height` texels tall.
void draw_text(cv::Mat& img, const cv::Rect& box, int height, int line_pitch, const cv::Scalar& ink,
               Rng& rng) {
  for (int y = box.y; y + height <= box.y + box.height; y += line_pitch) {
    int x = box.x;
    const int end = box.x + box.width - static_cast<int>(rng.uniform(0.0, 0.3) * box.width);
    while (x < end) {
      const int w = std::min(end - x, height + rng.below(6 * height));
      cv::rectangle(img, cv::Rect(x, y, w, height), ink, cv::FILLED, cv::LINE_AA);
      x += w + std::max(2, height);
    }
  }
}

cv::Mat to_float(const cv::Mat& img8) {
  cv::Mat rgb;
  img8.convertTo(rgb, CV_32FC3, 1.0 / 255.0);
  return rgb;
}

}  // namespace

cv::Mat poster(const MaterialSpec& spec, int size, Rng& rng) {
  const bool dark = rng.uniform() < 0.25;
  const cv::Scalar paper = dark ? random_color(rng, 0.05, 0.3)
                                : cv::Scalar(spec.color.x() * 255, spec.color.y() * 255, spec.color.z() * 255) *
                                      rng.uniform(0.85, 1.0);
  const cv::Scalar ink = dark ? random_color(rng, 0.7, 0.95) : random_color(rng, 0.0, 0.25);
  cv::Mat img(size, size, CV_8UC3, paper);
  const int margin = size / 16;
  const cv::Rect inner(margin, margin, size - 2 * margin, size - 2 * margin);
  // Layout from the top of the sheet (high t) down: heading, photographs, text columns.
  const int heading_h = size / 22;
  int y = inner.y + inner.height - 2 * heading_h;
  draw_text(img, cv::Rect(inner.x, y, inner.width, 2 * heading_h), heading_h, 2 * heading_h,
            random_color(rng, 0.0, 0.6), rng);
  const int photos = 1 + rng.below(3);
  const int photo_h = inner.height / (photos + 2);
  for (int i = 0; i < photos; ++i) {
    y -= photo_h + margin / 2;
    const int w = static_cast<int>(inner.width * rng.uniform(0.45, 1.0));
    const int x = inner.x + rng.below(std::max(1, inner.width - w));
    draw_photo(img, cv::Rect(x, y, w, photo_h), rng);
  }
  const int columns = 1 + rng.below(2);
  const int col_w = (inner.width - (columns - 1) * margin / 2) / columns;
  for (int c = 0; c < columns; ++c) {
    draw_text(img, cv::Rect(inner.x + c * (col_w + margin / 2), inner.y, col_w, y - inner.y - margin / 2),
              std::max(2, size / 110), std::max(5, size / 55), ink, rng);
  }
  if (rng.uniform() < 0.7) {
    const cv::Point logo(inner.x + inner.width - size / 10, inner.y + size / 12);
    cv::circle(img, logo, size / 24, random_color(rng, 0.1, 0.9), cv::FILLED, cv::LINE_AA);
    cv::circle(img, logo, size / 48, paper, cv::FILLED, cv::LINE_AA);
  }
  cv::Mat rgb = to_float(img);
  const float k = static_cast<float>(spec.contrast);
  if (k != 1.0f) {  // contrast scales every departure from the paper colour
    const cv::Vec3f p(static_cast<float>(paper[0] / 255), static_cast<float>(paper[1] / 255),
                      static_cast<float>(paper[2] / 255));
    for (int r = 0; r < size; ++r) {
      cv::Vec3f* o = rgb.ptr<cv::Vec3f>(r);
      for (int c = 0; c < size; ++c) o[c] = p + k * (o[c] - p);
    }
  }
  return rgb;
}

cv::Mat whiteboard(const MaterialSpec& spec, int size, Rng& rng) {
  const cv::Mat ghost = fractal_noise(size, 8, size / 4, 0.6, rng);
  cv::Mat img(size, size, CV_8UC3);
  for (int r = 0; r < size; ++r) {
    cv::Vec3b* o = img.ptr<cv::Vec3b>(r);
    const float* g = ghost.ptr<float>(r);
    for (int c = 0; c < size; ++c) {
      for (int ch = 0; ch < 3; ++ch)
        o[c][ch] = cv::saturate_cast<uchar>(255.0 * spec.color[ch] * (1.0 + 0.015 * static_cast<double>(g[c])));
    }
  }
  const cv::Scalar inks[3] = {{20, 40, 160}, {25, 25, 30}, {170, 30, 30}};
  const int strokes = static_cast<int>(std::round(spec.contrast * (2 + rng.below(6))));
  const int margin = size / 12;
  for (int s = 0; s < strokes; ++s) {
    std::vector<cv::Point> pts;
    cv::Point2d p(rng.uniform(margin, size - margin), rng.uniform(margin, size - margin));
    double heading = rng.uniform(0, 6.283185307179586);
    const int n = 4 + rng.below(20);
    for (int i = 0; i < n; ++i) {
      pts.emplace_back(static_cast<int>(p.x), static_cast<int>(p.y));
      heading += rng.uniform(-1.2, 1.2);
      const double step = rng.uniform(0.01, 0.04) * size;
      p.x = std::clamp(p.x + step * std::cos(heading), 1.0 * margin, 1.0 * (size - margin));
      p.y = std::clamp(p.y + step * std::sin(heading), 1.0 * margin, 1.0 * (size - margin));
    }
    cv::polylines(img, pts, false, inks[rng.below(3)], std::max(1, size / 200), cv::LINE_AA);
  }
  return to_float(img);
}

}  // namespace kestrel::sim::patterns
