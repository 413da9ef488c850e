#pragma once
// The simulated vehicle flies through walls where a real one would crash. ContactWatch follows
// the true body position and counts each time the vehicle's sphere starts touching the world,
// so that a closed-loop flight (planner, follower, controller on the estimator's state) can be
// checked for collisions. Observations are expected in time order; a contact lasts from the
// first position that touches until the first that does not.

#include <Eigen/Core>

#include "drivers/sim/world.h"

namespace kestrel::sim {

class ContactWatch {
 public:
  /// `world` must outlive the watch. Throws std::invalid_argument for a non-positive radius.
  ContactWatch(const World& world, double radius_m);

  /// The body is at p at time t_s; returns true when this starts a contact.
  bool observe(double t_s, const Eigen::Vector3d& p);

  int contacts() const { return contacts_; }
  /// Time of the first contact, or a negative value if there was none.
  double first_contact_s() const { return first_contact_s_; }
  /// Smallest distance from the body's centre to an obstacle so far (capped at 10 m).
  double min_clearance_m() const { return min_clearance_m_; }
  double radius_m() const { return radius_m_; }
  /// Forgets everything (a restarted simulation).
  void reset();

 private:
  const World& world_;
  double radius_m_;
  bool touching_ = false;
  int contacts_ = 0;
  double first_contact_s_ = -1.0;
  double min_clearance_m_ = 10.0;
};

}  // namespace kestrel::sim
