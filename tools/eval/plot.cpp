#include "tools/eval/plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "common/error.h"
#include "common/numbers.h"
#include "common/time.h"

namespace kestrel::eval {
namespace {

const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kInk(40, 40, 40);
const cv::Scalar kGrid(228, 228, 228);
const cv::Scalar kTruth(70, 70, 70);
const cv::Scalar kEstimate(200, 110, 20);  // blue
const cv::Scalar kVelocity(20, 120, 230);  // orange
const cv::Scalar kFailure(40, 40, 220);    // red
constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr int kShift = 4;  // sub-pixel drawing: coordinates in 1/16 px
constexpr int kWidth = 1000;

std::string tick_label(double v, double step) {
  const int decimals = std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9)));
  return fmt::format("{:.{}f}", std::abs(v) < 0.5 * step ? 0.0 : v, decimals);
}

void text(cv::Mat& img, const std::string& s, cv::Point at, double scale = 0.45,
          const cv::Scalar& colour = kInk, int thickness = 1) {
  cv::putText(img, s, at, kFont, scale, colour, thickness, cv::LINE_AA);
}
int text_width(const std::string& s, double scale = 0.45) {
  int baseline = 0;
  return cv::getTextSize(s, kFont, scale, 1, &baseline).width;
}

// A rectangle of the image showing the data range [x0, x1] x [y0, y1].
struct Axes {
  cv::Rect area;
  double x0, x1, y0, y1;

  cv::Point2d px(double x, double y) const {
    return {area.x + (x - x0) / (x1 - x0) * area.width,
            area.y + area.height - (y - y0) / (y1 - y0) * area.height};
  }
  cv::Point fixed(double x, double y) const {
    const cv::Point2d p = px(x, y) * (1 << kShift);
    return {static_cast<int>(std::lround(p.x)), static_cast<int>(std::lround(p.y))};
  }
  void line(cv::Mat& img, double xa, double ya, double xb, double yb, const cv::Scalar& c,
            int thickness) const {
    cv::line(img, fixed(xa, ya), fixed(xb, yb), c, thickness, cv::LINE_AA, kShift);
  }

  void grid(cv::Mat& img, double x_step, double y_step, const std::string& x_label,
            const std::string& y_label) const {
    for (double x = std::ceil(x0 / x_step) * x_step; x <= x1 + 1e-9 * x_step; x += x_step) {
      line(img, x, y0, x, y1, kGrid, 1);
      const std::string s = tick_label(x, x_step);
      text(img, s, cv::Point(static_cast<int>(px(x, y0).x) - text_width(s) / 2, area.br().y + 18));
    }
    for (double y = std::ceil(y0 / y_step) * y_step; y <= y1 + 1e-9 * y_step; y += y_step) {
      line(img, x0, y, x1, y, kGrid, 1);
      const std::string s = tick_label(y, y_step);
      text(img, s, cv::Point(area.x - 8 - text_width(s), static_cast<int>(px(x0, y).y) + 5));
    }
    cv::rectangle(img, area, kInk, 1);
    text(img, x_label, cv::Point(area.br().x - text_width(x_label), area.br().y + 38));
    text(img, y_label, cv::Point(std::max(8, area.x - 60), area.y - 10));
  }
};

// Polyline through the points whose `keep` is set, broken wherever one is not.
void polyline(cv::Mat& img, const Axes& axes, const std::vector<cv::Point2d>& points,
              const std::vector<bool>& keep, const cv::Scalar& colour, int thickness) {
  for (size_t i = 1; i < points.size(); ++i) {
    if (keep[i - 1] && keep[i])
      axes.line(img, points[i - 1].x, points[i - 1].y, points[i].x, points[i].y, colour, thickness);
  }
}

void top_view(cv::Mat& img, const cv::Rect& area, const metrics::Evaluation& e, bool aligned) {
  const Eigen::Isometry3d& T_gt_est = e.ate.alignment.T_gt_est;
  std::vector<cv::Point2d> gt, est;
  std::vector<bool> keep;
  for (const metrics::FramePoses& f : e.association.frames) {
    keep.push_back(f.scored());
    Eigen::Vector3d p_gt = Eigen::Vector3d::Zero();
    Eigen::Vector3d p_est = Eigen::Vector3d::Zero();
    if (f.T_world_gt) p_gt = f.T_world_gt->translation();
    if (f.T_world_est) p_est = T_gt_est * f.T_world_est->translation();
    gt.emplace_back(p_gt.x(), p_gt.y());
    est.emplace_back(p_est.x(), p_est.y());
  }
  double x0 = static_cast<double>(INFINITY), x1 = static_cast<double>(-INFINITY);
  double y0 = static_cast<double>(INFINITY), y1 = static_cast<double>(-INFINITY);
  for (size_t i = 0; i < gt.size(); ++i) {
    if (!keep[i]) continue;
    for (const cv::Point2d& p : {gt[i], est[i]}) {
      x0 = std::min(x0, p.x), x1 = std::max(x1, p.x);
      y0 = std::min(y0, p.y), y1 = std::max(y1, p.y);
    }
  }
  // Equal scale on both axes, 8 % margin, at least 10 cm across.
  const double half = 0.54 * std::max({x1 - x0, (y1 - y0) * area.width / area.height, 0.1});
  const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
  const double half_y = half * area.height / area.width;
  const Axes axes{area, cx - half, cx + half, cy - half_y, cy + half_y};
  const double step = nice_step(2.0 * half, 8);
  axes.grid(img, step, step, "x (m)", "y (m)");

  polyline(img, axes, gt, keep, kTruth, 2);
  polyline(img, axes, est, keep, kEstimate, 2);
  const auto first = std::find(keep.begin(), keep.end(), true) - keep.begin();
  for (const auto& [points, colour] : {std::pair{&gt, kTruth}, std::pair{&est, kEstimate}})
    cv::circle(img, axes.fixed((*points)[first].x, (*points)[first].y), 6 << kShift, colour, 2,
               cv::LINE_AA, kShift);

  // Scale bar, bottom left.
  const cv::Point2d bar0 = axes.px(axes.x0, axes.y0) + cv::Point2d(20, -20);
  const double bar_px = step / (axes.x1 - axes.x0) * area.width;
  cv::line(img, bar0, bar0 + cv::Point2d(bar_px, 0), kInk, 3);
  text(img, tick_label(step, step) + " m", bar0 + cv::Point2d(0, -10));

  // Legend, top right.
  const cv::Point corner(area.br().x - 230, area.y + 12);
  cv::rectangle(img, cv::Rect(corner, cv::Size(218, 76)), kWhite, cv::FILLED);
  cv::rectangle(img, cv::Rect(corner, cv::Size(218, 76)), kInk, 1);
  const std::string est_label = aligned ? "estimate (aligned)" : "estimate";
  int y = corner.y + 20;
  for (const auto& [label, colour] :
       {std::pair{std::string("ground truth"), kTruth}, std::pair{est_label, kEstimate}}) {
    cv::line(img, cv::Point(corner.x + 10, y - 4), cv::Point(corner.x + 50, y - 4), colour, 2,
             cv::LINE_AA);
    text(img, label, cv::Point(corner.x + 60, y));
    y += 24;
  }
  cv::circle(img, cv::Point(corner.x + 30, y - 4), 6, kInk, 2, cv::LINE_AA);
  text(img, "start", cv::Point(corner.x + 60, y));
}

// An error over time: a line through `values` at `utimes` (broken where consecutive values
// are more than 1.5 frame intervals apart), red marks at the `failures` times.
void time_series(cv::Mat& img, const cv::Rect& area, int64_t t0_us, double duration_s,
                 const std::vector<int64_t>& utimes, const std::vector<double>& values,
                 const std::vector<int64_t>& failures, const cv::Scalar& colour,
                 const std::string& label, double threshold) {
  double top = 0.0;
  for (double v : values) top = std::max(top, v);
  const bool show_threshold = std::isfinite(threshold) && threshold <= 2.0 * top;
  if (show_threshold) top = std::max(top, threshold);
  // A floor of 1 mm (or 1 mm/s, 1e-3 deg): below it the ticks would be rounding noise.
  top = std::max(1.1 * top, 1e-3);
  const Axes axes{area, 0.0, std::max(duration_s, 1e-3), 0.0, top};
  std::string full_label = label;
  if (show_threshold) full_label += fmt::format("; dashed: {:g}", threshold);
  if (!failures.empty()) full_label += "; triangles: gross failures";
  axes.grid(img, nice_step(axes.x1, 10), nice_step(top, 4), "time (s)", full_label);

  std::vector<cv::Point2d> points;
  std::vector<bool> keep;
  for (size_t i = 0; i < utimes.size(); ++i) {
    points.emplace_back(to_seconds(utimes[i] - t0_us), values[i]);
    keep.push_back(true);
  }
  double frame_s = static_cast<double>(INFINITY);
  for (size_t i = 1; i < points.size(); ++i)
    frame_s = std::min(frame_s, points[i].x - points[i - 1].x);
  for (size_t i = 1; i < points.size(); ++i) {
    if (points[i].x - points[i - 1].x <= 1.5 * frame_s)
      axes.line(img, points[i - 1].x, points[i - 1].y, points[i].x, points[i].y, colour, 2);
  }
  for (const cv::Point2d& p : points)
    cv::circle(img, axes.px(p.x, p.y), 2, colour, cv::FILLED, cv::LINE_AA);
  if (show_threshold) {
    for (double x = 0.0; x < axes.x1; x += axes.x1 / 60.0)
      axes.line(img, x, threshold, std::min(x + axes.x1 / 120.0, axes.x1), threshold, kFailure, 1);
  }
  for (int64_t t : failures) {
    const cv::Point2d p = axes.px(to_seconds(t - t0_us), 0.0);
    const std::vector<cv::Point> mark = {cv::Point(p.x, p.y - 10), cv::Point(p.x - 5, p.y),
                                         cv::Point(p.x + 5, p.y)};
    cv::fillConvexPoly(img, mark, kFailure, cv::LINE_AA);
  }
}

}  // namespace

cv::Mat render_plot(const metrics::Evaluation& e, const metrics::EvalOptions& options, const std::string& title) {
  cv::Mat img(1390, kWidth, CV_8UC3, kWhite);
  text(img, title, cv::Point(20, 30), 0.6, kInk, 1);
  const metrics::GrossFailures& g = e.velocity.gross;
  text(img,
       fmt::format("ATE {:.3f} m   RPE {:.3f} m/s, {:.2f} deg/s   velocity error {:.3f} m/s   "
                   "gross failures {:.2f} %",
                   e.ate.error_m.rmse, e.rpe.translation_mps.rmse, e.rpe.rotation_degps.rmse,
                   e.velocity.error_mps.mean, g.percent()),
       cv::Point(20, 56), 0.5);
  top_view(img, cv::Rect(90, 100, 860, 700), e, options.align);

  const auto& frames = e.association.frames;
  const int64_t t0 = frames.front().utime;
  const double duration = to_seconds(frames.back().utime - t0);
  std::vector<int64_t> failures;
  for (size_t k = 0; k < frames.size(); ++k) {
    if (is_gross(e.velocity.verdicts[k])) failures.push_back(frames[k].utime);
  }
  time_series(img, cv::Rect(90, 880, 860, 190), t0, duration, e.ate.utimes, e.ate.errors_m, {},
              kEstimate, "ATE position error (m)", static_cast<double>(NAN));
  time_series(img, cv::Rect(90, 1140, 860, 190), t0, duration, e.velocity.utimes,
              e.velocity.errors_mps, failures, kVelocity, "velocity error (m/s)",
              options.gross_velocity_mps);
  return img;
}

}  // namespace kestrel::eval
