#pragma once
// Cell addressing, exactly as OctoMap does it (OcTreeBaseImpl::coordToKeyChecked, keyToCoord),
// so that a key computed here names the same cell as one computed by an octomap::OcTree of
// the same resolution: key = floor(coordinate / resolution) + 32768, 16 bits per axis, tree
// depth 16. Cell k covers [ (k - 32768) * res, (k - 32767) * res ).

// OcTreeKey.h uses size_t and std::vector without including their headers.
#include <cstddef>
#include <vector>

#include <octomap/OcTreeKey.h>
#include <octomap/octomap_types.h>

#include <cmath>
#include <cstdint>

namespace kestrel::mapper {

using Key = octomap::OcTreeKey;

class KeySpace {
 public:
  static constexpr int kTreeDepth = 16;
  static constexpr int kMaxVal = 32768;  ///< key of the cell whose lower corner is at 0

  explicit KeySpace(double resolution_m)
      : resolution_(resolution_m), factor_(1.0 / resolution_m) {}

  double resolution() const { return resolution_; }
  /// 1 / resolution: key(c) is floor(factor() * c) + kMaxVal.
  double factor() const { return factor_; }

  /// The key along one axis; false outside the tree (or for a non-finite coordinate).
  bool key(double coordinate, uint16_t& k) const {
    const double scaled = factor_ * coordinate;
    // floor(s) >= -kMaxVal iff s >= -kMaxVal, and floor(s) < kMaxVal iff s < kMaxVal, so the
    // range is checked before flooring; the negated comparison also rejects NaN before the
    // cast, which would be undefined. Then floor is the truncation, minus one for a negative
    // non-integer (std::floor is a long instruction sequence on the baseline x86-64 target).
    if (!(scaled >= -kMaxVal && scaled < kMaxVal)) return false;
    int floored = static_cast<int>(scaled);
    floored -= static_cast<int>(scaled < static_cast<double>(floored));
    k = static_cast<uint16_t>(floored + kMaxVal);
    return true;
  }
  bool key(const octomap::point3d& p, Key& k) const {
    return key(static_cast<double>(p.x()), k[0]) && key(static_cast<double>(p.y()), k[1]) &&
           key(static_cast<double>(p.z()), k[2]);
  }
  bool key(double x, double y, double z, Key& k) const {
    return key(x, k[0]) && key(y, k[1]) && key(z, k[2]);
  }

  /// The smallest float coordinate whose key is >= k (so key k's floats are
  /// [first_float(k), first_float(k + 1))): key() of a float is monotonic in it, so a float
  /// can be placed in a cell by comparisons alone. k within the key range.
  float first_float(int k) const {
    const double n = static_cast<double>(k - kMaxVal);
    float x = static_cast<float>(n * resolution_);
    while (factor_ * static_cast<double>(x) >= n) x = std::nextafter(x, -HUGE_VALF);
    while (!(factor_ * static_cast<double>(x) >= n)) x = std::nextafter(x, HUGE_VALF);
    return x;
  }

  /// Centre of cell k along one axis (OctoMap's keyToCoord).
  double centre(uint16_t k) const {
    return (static_cast<double>(static_cast<int>(k) - kMaxVal) + 0.5) * resolution_;
  }
  /// Lower and upper bound of cell k along one axis.
  double lower(uint16_t k) const {
    return static_cast<double>(static_cast<int>(k) - kMaxVal) * resolution_;
  }
  double upper(uint16_t k) const {
    return static_cast<double>(static_cast<int>(k) - kMaxVal + 1) * resolution_;
  }

 private:
  double resolution_;
  double factor_;
};

}  // namespace kestrel::mapper
