#include "drivers/kinect/accelerometer.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kestrel::kinect {

int16_t mps2_to_counts(double a) {
  const double counts = std::round(a / kStandardGravity * kCountsPerG);
  if (std::isnan(counts)) return 0;
  constexpr double lo = std::numeric_limits<int16_t>::min();
  constexpr double hi = std::numeric_limits<int16_t>::max();
  return static_cast<int16_t>(std::clamp(counts, lo, hi));
}

}  // namespace kestrel::kinect
