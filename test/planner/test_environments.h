#pragma once
// Environments with analytic free space for the planner's tests: free wherever a predicate
// holds (no workspace walls), sampled inside a given box.
#include <functional>

#include "planner/environment.h"

namespace kestrel::planner::testing {

class PredicateEnvironment : public Environment {
 public:
  PredicateEnvironment(Eigen::AlignedBox3d box, std::function<bool(const Eigen::Vector3d&)> free)
      : box_(box), free_(std::move(free)) {}
  Eigen::AlignedBox3d bounds() const override { return box_; }
  bool is_free(const Eigen::Vector3d& p, double) const override { return free_(p); }
  bool segment_is_free(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double) const override {
    for (int i = 0; i <= 100; ++i)
      if (!free_(a + (b - a) * (i / 100.0))) return false;
    return true;
  }
  bool line_of_sight(const Eigen::Vector3d&, const Eigen::Vector3d&) const override { return true; }

 private:
  Eigen::AlignedBox3d box_;
  std::function<bool(const Eigen::Vector3d&)> free_;
};

}  // namespace kestrel::planner::testing
