#include "common/camera.h"

#include <cmath>

#include "common/error.h"
#include "common/numbers.h"
#include "common/text.h"

namespace kestrel {

PinholeCamera PinholeCamera::scaled(double s) const {
  PinholeCamera c = *this;
  c.width = static_cast<int>(std::lround(width * s));
  c.height = static_cast<int>(std::lround(height * s));
  c.fx = fx * s;
  c.fy = fy * s;
  // Pixel centres, not corners, scale: (u + 0.5) * s - 0.5.
  c.cx = (cx + 0.5) * s - 0.5;
  c.cy = (cy + 0.5) * s - 0.5;
  return c;
}

bool PinholeCamera::distorted() const {
  for (double k : distortion) {
    if (k != 0.0) return true;
  }
  return false;
}

Eigen::Vector2d PinholeCamera::distort_normalized(double x, double y, Eigen::Matrix2d* jacobian) const {
  const double k1 = distortion[0], k2 = distortion[1], p1 = distortion[2], p2 = distortion[3],
               k3 = distortion[4];
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k1 + r2 * (k2 + r2 * k3));
  if (jacobian) {
    const double dradial = k1 + r2 * (2.0 * k2 + 3.0 * r2 * k3);  // d radial / d r2
    const double jxy = 2.0 * x * y * dradial + 2.0 * p1 * x + 2.0 * p2 * y;  // symmetric
    *jacobian << radial + 2.0 * x * x * dradial + 2.0 * p1 * y + 6.0 * p2 * x, jxy,  //
        jxy, radial + 2.0 * y * y * dradial + 6.0 * p1 * y + 2.0 * p2 * x;
  }
  return {x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
          y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y};
}

Eigen::Vector2d PinholeCamera::distort(double u, double v) const {
  if (!distorted()) return {u, v};  // exactly, not through the normalised coordinates
  const Eigen::Vector2d d = distort_normalized((u - cx) / fx, (v - cy) / fy);
  return {fx * d.x() + cx, fy * d.y() + cy};
}

void PinholeCamera::validate(const char* what) const {
  const bool ok = width > 0 && height > 0 && width <= 16384 && height <= 16384 &&
                  std::isfinite(fx) && std::isfinite(fy) && std::isfinite(cx) &&
                  std::isfinite(cy) && fx > 0.0 && fy > 0.0;
  if (!ok) {
    throw InputError(std::string(what) + ": invalid camera (" + std::to_string(width) + "x" +
                     std::to_string(height) + ", fx=" + std::to_string(fx) +
                     ", fy=" + std::to_string(fy) + ")");
  }
  for (double k : distortion) {
    if (!std::isfinite(k)) throw InputError(std::string(what) + ": non-finite lens distortion coefficient");
  }
}

// The bounds are deliberately loose: they reject impossible cameras, not unusual ones.
void check_plausible_camera(const PinholeCamera& c, const Eigen::Isometry3d& T_body_camera,
                            const char* what) {
  auto fail = [&](const std::string& why) {
    throw InputError(std::string(what) + ": implausible camera: " + why);
  };
  const double max_half_fov_rad = 85.0 * kDegree, min_half_fov_rad = 0.005 * kDegree;
  auto check_focal = [&](const char* name, double f_px, int pixels, const char* side) {
    if (f_px < 0.5 * pixels / std::tan(max_half_fov_rad) || f_px > 0.5 * pixels / std::tan(min_half_fov_rad))
      fail(std::string(name) + " = " + number_text(f_px) + " px for images " + std::to_string(pixels) +
           " px " + side + " (a field of view outside 0.01..170 deg)");
  };
  check_focal("fx", c.fx, c.width, "wide");
  check_focal("fy", c.fy, c.height, "high");
  auto check_centre = [&](const char* name, double centre_px, int pixels, const char* side) {
    if (centre_px < -pixels || centre_px > 2.0 * pixels)
      fail(std::string(name) + " = " + number_text(centre_px) + " px, more than an image outside images " +
           std::to_string(pixels) + " px " + side);
  };
  check_centre("cx", c.cx, c.width, "wide");
  check_centre("cy", c.cy, c.height, "high");
  for (double k : c.distortion)
    if (std::abs(k) > 1e3) fail("lens distortion coefficient " + number_text(k) + " (beyond +-1000)");
  const double offset_m = T_body_camera.translation().norm();
  if (offset_m > 100.0) fail("mounted " + number_text(offset_m) + " m from the body (more than 100 m)");
}


}  // namespace kestrel
