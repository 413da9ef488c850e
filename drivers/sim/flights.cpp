#include "drivers/sim/flights.h"

#include <cmath>
#include <stdexcept>

#include "common/numbers.h"
#include "drivers/sim/route.h"

namespace kestrel::sim {
namespace {

// a sin(w tau + phase), with its first two derivatives.
struct Wave {
  double amplitude, omega, phase;
  double value(double tau) const { return amplitude * std::sin(omega * tau + phase); }
  double rate(double tau) const { return amplitude * omega * std::cos(omega * tau + phase); }
  double accel(double tau) const { return -amplitude * omega * omega * std::sin(omega * tau + phase); }
};

// A path whose coordinates in a local frame (forward, left, up, yaw) are offsets plus sums of
// sines: hover drift, figure eights and ellipses are all of this form, and differentiate
// exactly.
class HarmonicFlight : public Flight {
 public:
  HarmonicFlight(std::string name, const Eigen::Vector4d& origin, double ramp_s)
      : Flight(ramp_s), name_(std::move(name)), origin_(origin) {}
  void add(int axis, Wave wave) { waves_[axis].push_back(wave); }

  std::string name() const override { return name_; }
  PathPoint path(double tau) const override {
    double value[4] = {0, 0, 0, 0}, rate[4] = {0, 0, 0, 0}, accel[4] = {0, 0, 0, 0};
    for (int axis = 0; axis < 4; ++axis)
      for (const Wave& w : waves_[axis]) {
        value[axis] += w.value(tau);
        rate[axis] += w.rate(tau);
        accel[axis] += w.accel(tau);
      }
    const double c = std::cos(origin_[3]), s = std::sin(origin_[3]);
    auto to_world = [&](const double* q) { return Eigen::Vector3d(c * q[0] - s * q[1], s * q[0] + c * q[1], q[2]); };
    PathPoint out;
    out.p = origin_.head<3>() + to_world(value);
    out.v = to_world(rate);
    out.a = to_world(accel);
    out.yaw = origin_[3] + value[3];
    return out;
  }

 private:
  std::string name_;
  Eigen::Vector4d origin_;  // x, y, z, yaw of the local frame
  std::vector<Wave> waves_[4];
};

std::unique_ptr<Flight> hover(const World& world, const FlightOptions& o) {
  auto f = std::make_unique<HarmonicFlight>("hover", world.start(), o.ramp_s);
  const double k = o.speed_scale;
  f->add(0, {0.04, k * 2 * kPi / 7.3, 0.0});
  f->add(1, {0.03, k * 2 * kPi / 11.1, 1.0});
  f->add(2, {0.02, k * 2 * kPi / 5.7, 2.0});
  f->add(3, {0.05, k * 2 * kPi / 9.1, 0.5});
  return f;
}

// Lemniscate of Gerono across the view: left = A sin(theta), forward = B sin(2 theta).
std::unique_ptr<Flight> figure_eight(const std::string& name, const World& world, const FlightOptions& o,
                                     double scale, bool aggressive) {
  auto f = std::make_unique<HarmonicFlight>(name, world.start(), o.ramp_s);
  const double w = (aggressive ? 0.75 : 0.4) * o.speed_scale;
  const double lateral = (aggressive ? 1.8 : 1.5) * scale, forward = (aggressive ? 0.35 : 0.5) * scale;
  f->add(1, {lateral, w, 0.0});
  f->add(0, {forward, 2 * w, 0.0});
  f->add(2, {aggressive ? 0.3 * scale : 0.1 * scale, 2 * w, 1.0});
  if (aggressive) {
    f->add(3, {0.45, w, 0.0});
    f->add(3, {0.75, 3 * w, 0.0});
  } else {
    f->add(3, {25.0 * kPi / 180.0, w, 0.0});
  }
  return f;
}

// An ellipse around the middle of the world, facing outwards (towards the walls): its yaw
// grows steadily (w tau), which is not a sum of sines.
class EllipseFlight : public Flight {
 public:
  EllipseFlight(const Eigen::Vector3d& centre, double a, double b, double omega, double ramp_s)
      : Flight(ramp_s), centre_(centre), a_(a), b_(b), w_(omega) {}
  std::string name() const override { return "loop"; }
  PathPoint path(double tau) const override {
    const double c = std::cos(w_ * tau), s = std::sin(w_ * tau);
    PathPoint out;
    out.p = centre_ + Eigen::Vector3d(a_ * c, b_ * s, 0.0);
    out.v = Eigen::Vector3d(-a_ * w_ * s, b_ * w_ * c, 0.0);
    out.a = Eigen::Vector3d(-a_ * w_ * w_ * c, -b_ * w_ * w_ * s, 0.0);
    out.yaw = w_ * tau;
    return out;
  }

 private:
  Eigen::Vector3d centre_;
  double a_, b_, w_;
};

std::unique_ptr<Flight> outward_ellipse(const World& world, const FlightOptions& o, double scale) {
  const Eigen::Vector3d centre = world.bounds().center();
  const Eigen::Vector3d half = 0.5 * world.bounds().sizes();
  const double a = (half.x() - 1.5) * scale, b = (half.y() - 1.5) * scale;
  if (!(a > 0.5 && b > 0.5)) return nullptr;
  const double w = 0.6 * o.speed_scale / (0.5 * (a + b));
  return std::make_unique<EllipseFlight>(Eigen::Vector3d(centre.x(), centre.y(), world.start().z()), a, b, w,
                                         o.ramp_s);
}

std::unique_ptr<Flight> tour(const std::string& name, const World& world, const FlightOptions& o, int stops,
                             double speed) {
  RouteOptions ro;
  ro.height_m = world.start().z() - world.bounds().min().z();
  ro.stops = stops;
  const auto points = plan_tour(world, world.start().head<2>(), ro);
  return std::make_unique<SplineFlight>(name, points, speed * o.speed_scale, o.ramp_s);
}

// Tries a flight family at shrinking sizes until one is collision-free over its period.
template <class Make>
std::unique_ptr<Flight> fitted(const World& world, const FlightOptions& o, double period_s, Make make) {
  double scale = 1.0;
  for (int attempt = 0; attempt < 8; ++attempt, scale *= 0.8) {
    std::unique_ptr<Flight> f = make(scale);
    if (f && first_collision(*f, world, o.radius_m, o.ramp_s + period_s) < 0) return f;
  }
  return nullptr;
}

}  // namespace

std::vector<std::string> flight_names() { return {"hover", "figure8", "aggressive", "loop", "survey"}; }

double first_collision(const Flight& flight, const World& world, double radius_m, double duration_s) {
  for (double t = 0.0; t <= duration_s; t += 0.05)
    if (!world.is_free(flight.point(t).p, radius_m)) return t;
  return -1.0;
}

std::unique_ptr<Flight> make_flight(const std::string& name, const World& world, const FlightOptions& o) {
  std::unique_ptr<Flight> f;
  if (name == "hover") {
    f = fitted(world, o, 120.0, [&](double) { return hover(world, o); });
  } else if (name == "figure8" || name == "aggressive") {
    const bool aggressive = name == "aggressive";
    const double period = 2 * kPi / ((aggressive ? 0.75 : 0.4) * o.speed_scale);
    f = fitted(world, o, period, [&](double s) { return figure_eight(name, world, o, s, aggressive); });
  } else if (name == "loop") {
    if (!world.free_mask()) {
      f = fitted(world, o, 60.0, [&](double s) { return outward_ellipse(world, o, s); });
    }
    if (!f) {
      auto spline = tour(name, world, o, 4, 0.6);
      const double period = static_cast<const SplineFlight&>(*spline).period_s();
      if (first_collision(*spline, world, o.radius_m, o.ramp_s + period) < 0) f = std::move(spline);
    }
  } else if (name == "survey") {
    auto spline = tour(name, world, o, 6, 0.4);
    const double period = static_cast<const SplineFlight&>(*spline).period_s();
    if (first_collision(*spline, world, o.radius_m, o.ramp_s + period) < 0) f = std::move(spline);
  } else {
    std::string known;
    for (const auto& n : flight_names()) known += (known.empty() ? "" : ", ") + n;
    throw std::invalid_argument("unknown flight '" + name + "' (known: " + known + ")");
  }
  if (!f) throw std::runtime_error("flight '" + name + "' does not fit world '" + world.name() + "' without collision");
  return f;
}

SplineFlight::SplineFlight(std::string name, const std::vector<Eigen::Vector3d>& points, double speed,
                           double ramp_s)
    : Flight(ramp_s),
      name_(std::move(name)),
      position_(points, (points.size() > 1 ? (points[1] - points[0]).norm() : 1.0) / speed),
      yaw_(std::vector<Eigen::Vector3d>(points.size(), Eigen::Vector3d::Zero()), 1.0) {
  const size_t n = points.size();
  std::vector<double> heading(n + 1);
  for (size_t i = 0; i <= n; ++i) {
    const Eigen::Vector3d d = points[(i + 1) % n] - points[(i + n - 1) % n];
    heading[i] = std::atan2(d.y(), d.x());
    if (i > 0) heading[i] = heading[i - 1] + std::remainder(heading[i] - heading[i - 1], 2 * kPi);
  }
  yaw_turn_ = heading[n] - heading[0];
  std::vector<Eigen::Vector3d> yaw_points(n, Eigen::Vector3d::Zero());
  for (size_t i = 0; i < n; ++i) yaw_points[i].x() = heading[i] - yaw_turn_ * static_cast<double>(i) / n;
  const double knot_dt = position_.period_s() / static_cast<double>(n);
  yaw_ = PeriodicBSpline(yaw_points, knot_dt);
}

PathPoint SplineFlight::path(double tau) const {
  PathPoint out;
  out.p = position_.derivative(tau, 0);
  out.v = position_.derivative(tau, 1);
  out.a = position_.derivative(tau, 2);
  // B-splines reproduce linear functions: sum_j (i + j) B_j(u) = i + u + (degree - 1) / 2.
  const double n = static_cast<double>(position_.control_points().size());
  const double knot_dt = position_.period_s() / n;
  out.yaw = yaw_.position(tau).x() + yaw_turn_ * (tau / knot_dt + 0.5 * (PeriodicBSpline::kDegree - 1)) / n;
  return out;
}

}  // namespace kestrel::sim
