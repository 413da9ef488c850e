#include "drivers/kinect/disparity_model.h"

#include <cmath>
#include <stdexcept>

namespace kestrel::kinect {

double DisparityModel::metres(uint16_t raw) const {
  if (raw >= kNoReading) return 0.0;
  const double inverse_depth = a * raw + b;
  return inverse_depth > 0.0 ? 1.0 / inverse_depth : 0.0;
}

uint16_t DisparityModel::raw(double z_m) const {
  if (!std::isfinite(z_m) || z_m <= 0.0) return kNoReading;
  const double fractional = (1.0 / z_m - b) / a;
  // Less than one raw step nearer than raw 0 is raw 0: depth that raw 0 produced and that was
  // then rounded to whole millimetres (0.3002 m -> 300 mm) must map back to it.
  const double r = fractional > -1.0 && fractional < 0.0 ? 0.0 : std::round(fractional);
  // The negated test also rejects NaN; a rounded value whose depth is not positive (beyond
  // raw -b/a) cannot be told apart from "no reading" by the driver, so it is one.
  if (!(r >= 0.0 && r < kNoReading)) return kNoReading;
  const auto raw_value = static_cast<uint16_t>(r);
  return metres(raw_value) > 0.0 ? raw_value : kNoReading;
}

double DisparityModel::step_at(double z_m) const { return std::abs(a) * z_m * z_m; }

void DisparityModel::validate() const {
  if (!(std::isfinite(a) && std::isfinite(b) && a < 0.0 && b > 0.0))
    throw std::invalid_argument("disparity model needs finite a < 0 < b");
}

std::array<float, 2048> DisparityModel::table() const {
  std::array<float, 2048> t{};
  for (size_t raw = 0; raw < t.size(); ++raw) t[raw] = static_cast<float>(metres(static_cast<uint16_t>(raw)));
  return t;
}

}  // namespace kestrel::kinect
