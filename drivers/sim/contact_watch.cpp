#include "drivers/sim/contact_watch.h"

#include <algorithm>
#include <stdexcept>

namespace kestrel::sim {

ContactWatch::ContactWatch(const World& world, double radius_m) : world_(world), radius_m_(radius_m) {
  if (!(radius_m > 0.0)) throw std::invalid_argument("ContactWatch: the radius must be > 0");
}

bool ContactWatch::observe(double t_s, const Eigen::Vector3d& p) {
  min_clearance_m_ = std::min(min_clearance_m_, world_.clearance(p));
  // is_free also refuses positions outside the world (off a map world's free cells).
  const bool touching = !world_.is_free(p, radius_m_);
  const bool starts = touching && !touching_;
  touching_ = touching;
  if (!starts) return false;
  if (contacts_++ == 0) first_contact_s_ = t_s;
  return true;
}

void ContactWatch::reset() {
  touching_ = false;
  contacts_ = 0;
  first_contact_s_ = -1.0;
  min_clearance_m_ = 10.0;
}

}  // namespace kestrel::sim
