#include "common/camera.h"

#include <cmath>

#include "common/error.h"

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

void PinholeCamera::validate(const char* what) const {
  const bool ok = width > 0 && height > 0 && width <= 16384 && height <= 16384 &&
                  std::isfinite(fx) && std::isfinite(fy) && std::isfinite(cx) &&
                  std::isfinite(cy) && fx > 0.0 && fy > 0.0;
  if (!ok) {
    throw InputError(std::string(what) + ": invalid camera (" + std::to_string(width) + "x" +
                     std::to_string(height) + ", fx=" + std::to_string(fx) +
                     ", fy=" + std::to_string(fy) + ")");
  }
}

}  // namespace kestrel
