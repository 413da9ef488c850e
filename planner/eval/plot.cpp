// draw_plans: OpenCV drawing of free space, samples and paths with covariance ellipses.
#include "planner/eval/plot.h"

#include "common/numbers.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <opencv2/imgproc.hpp>

namespace kestrel::planner::eval {

cv::Scalar track_colour(double value, double full_scale) {
  const double s = std::clamp(value / full_scale, 0.0, 1.0);
  // green (0, 170, 0) -> yellow (0, 200, 230) -> red (0, 0, 220), BGR
  return s < 0.5 ? cv::Scalar(0, 170 + 60 * s, 460 * s) : cv::Scalar(0, 200 - 400 * (s - 0.5), 230 - 20 * (s - 0.5));
}

cv::Point to_pixel(const Environment& env, const Eigen::Vector3d& p, double ppm) {
  const Eigen::AlignedBox3d b = env.bounds();
  return {static_cast<int>((p.x() - b.min().x()) * ppm), static_cast<int>((b.max().y() - p.y()) * ppm)};
}

cv::Mat crop_to(const cv::Mat& image, const Environment& env, const std::vector<Eigen::Vector3d>& points,
                double margin_m, double ppm) {
  if (points.empty()) return image;
  cv::Rect box(to_pixel(env, points.front(), ppm), cv::Size(1, 1));
  for (const Eigen::Vector3d& p : points) box |= cv::Rect(to_pixel(env, p, ppm), cv::Size(1, 1));
  const int margin = static_cast<int>(std::ceil(margin_m * ppm));
  box -= cv::Point(margin, margin);
  box += cv::Size(2 * margin, 2 * margin);
  box &= cv::Rect(0, 0, image.cols, image.rows);
  return box.area() > 0 ? image(box).clone() : image;
}

cv::Mat draw_plans(const Environment& env, const std::vector<Config>& samples, const std::vector<DrawnPath>& paths,
                   double z_m, double ppm, const std::vector<DrawnTrack>& tracks) {
  const Eigen::AlignedBox3d b = env.bounds();
  const int w = static_cast<int>(std::ceil((b.max().x() - b.min().x()) * ppm));
  const int h = static_cast<int>(std::ceil((b.max().y() - b.min().y()) * ppm));
  cv::Mat img(h, w, CV_8UC3);
  const auto px = [&](const Eigen::Vector3d& p) { return to_pixel(env, p, ppm); };
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      const Eigen::Vector3d p(b.min().x() + (c + 0.5) / ppm, b.max().y() - (r + 0.5) / ppm, z_m);
      img.at<cv::Vec3b>(r, c) = env.is_free(p, 0.5 / ppm) ? cv::Vec3b(255, 255, 255) : cv::Vec3b(40, 40, 40);
    }
  for (const Feature& f : env.features()) cv::circle(img, px(f.position), 1, cv::Scalar(0, 160, 0), cv::FILLED);
  for (const Config& q : samples) cv::circle(img, px(position(q)), 3, cv::Scalar(200, 120, 0), cv::FILLED);
  for (const DrawnTrack& t : tracks)
    for (size_t i = 1; i < t.points.size() && i < t.values.size(); ++i)
      cv::line(img, px(t.points[i - 1]), px(t.points[i]), track_colour(t.values[i], t.full_scale), t.thickness,
               cv::LINE_AA);
  for (const DrawnPath& path : paths) {
    for (size_t i = 1; i < path.nodes.size(); ++i)
      cv::line(img, px(position(path.nodes[i - 1])), px(position(path.nodes[i])), path.colour, 2, cv::LINE_AA);
    for (size_t i = 0; i < path.covariances.size() && i < path.nodes.size(); ++i) {
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix2d> es(path.covariances[i].topLeftCorner<2, 2>());
      const Eigen::Vector2d axes = es.eigenvalues().cwiseMax(0.0).cwiseSqrt() * ppm;
      const Eigen::Vector2d major = es.eigenvectors().col(1);
      const double angle = -std::atan2(major.y(), major.x()) * 180.0 / kPi;  // image y is down
      cv::ellipse(img, px(position(path.nodes[i])), cv::Size(std::max(1, static_cast<int>(axes[1])), std::max(1, static_cast<int>(axes[0]))),
                  angle, 0, 360, path.colour, 1, cv::LINE_AA);
    }
  }
  return img;
}

}  // namespace kestrel::planner::eval
