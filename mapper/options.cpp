#include "mapper/options.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace kestrel::mapper {

namespace {
void require(bool ok, const char* field, const std::string& what) {
  if (!ok) throw std::invalid_argument(std::string(field) + ": " + what);
}
bool is_probability(double p) { return std::isfinite(p) && p > 0.0 && p < 1.0; }
}  // namespace

void MapOptions::validate() const {
  require(std::isfinite(resolution_m) && resolution_m >= 0.005 && resolution_m <= 10.0,
          "resolution", "must be between 0.005 and 10 m");
  require(is_probability(prob_hit) && prob_hit > 0.5, "prob-hit", "must be in (0.5, 1)");
  require(is_probability(prob_miss) && prob_miss < 0.5, "prob-miss", "must be in (0, 0.5)");
  require(is_probability(clamp_min) && is_probability(clamp_max) && clamp_min < clamp_max,
          "clamp-min/clamp-max", "must be probabilities with clamp-min < clamp-max");
  require(is_probability(occupancy_threshold), "occupancy-threshold", "must be in (0, 1)");
  require(std::isfinite(decay_half_life_s) && decay_half_life_s >= 0.0, "decay-half-life",
          "must be >= 0 (0 = off)");
  require(std::isfinite(decay_period_s) && decay_period_s > 0.0, "decay-period", "must be > 0");
  require(std::isfinite(forget_below) && forget_below >= 0.0, "forget-below", "must be >= 0");
}

void ScanOptions::validate() const {
  require(stride >= 1 && stride <= 64, "stride", "must be between 1 and 64");
  require(std::isfinite(max_range_m) && max_range_m > 0.0 && max_range_m <= 50.0, "max-range",
          "must be in (0, 50] m");
  require(std::isfinite(min_range_m) && min_range_m >= 0.0 && min_range_m < max_range_m,
          "min-range", "must be >= 0 and below max-range");
}

}  // namespace kestrel::mapper
