#include "drivers/sim/vehicle.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/numbers.h"

namespace kestrel::sim {
namespace {

Eigen::Vector3d clamp_norm(const Eigen::Vector3d& x, double limit) {
  const double n = x.norm();
  return n > limit ? Eigen::Vector3d(x * (limit / n)) : x;
}

}  // namespace

ControlOutput control(const VehicleCommand& command, const VehicleEstimate& estimate, const VehicleOptions& o) {
  Eigen::Vector3d v_target;
  ControlOutput out;
  if (command.mode == VehicleCommand::kVelocity) {
    v_target = command.velocity;
    out.yaw_rate = command.yaw_rate;
  } else {  // kPosition (a hold is latched into a position by VehicleLoop)
    v_target = clamp_norm(o.position_gain * (command.position - estimate.p), o.max_speed_m_s) + command.velocity;
    out.yaw_rate = o.yaw_gain * wrap_angle(command.yaw - estimate.yaw) + command.yaw_rate;
  }
  v_target = clamp_norm(v_target, o.max_speed_m_s);
  out.yaw_rate = std::clamp(out.yaw_rate, -o.max_yaw_rate, o.max_yaw_rate);
  out.accel = clamp_norm(o.velocity_gain * (v_target - estimate.v), o.max_accel_m_s2);
  return out;
}

VehicleCommand hold_at(const Eigen::Vector4d& pose) {
  VehicleCommand c;
  c.mode = VehicleCommand::kPosition;
  c.position = pose.head<3>();
  c.yaw = pose[3];
  return c;
}

VehicleFlight::VehicleFlight(const Eigen::Vector4d& start, const VehicleOptions& options, uint64_t seed)
    : Flight(0.0), start_(start), options_(options), seed_(seed), wind_rng_(derive(seed, tag("wind"))) {
  if (!(options_.control_period_s > 0 && options_.response_s > 0 && options_.yaw_response_s > 0 &&
        options_.wind_time_s > 0 && options_.history_s > 0))
    throw std::invalid_argument("VehicleOptions: periods, response and correlation times must be > 0");
}

void VehicleFlight::reset() {
  history_.clear();
  first_step_ = 0;
  end_s_ = 0.0;
  wind_ = Eigen::Vector3d::Zero();
  wind_rng_ = Rng(derive(seed_, tag("wind")));
}

PathPoint VehicleFlight::evaluate(const Segment& s, double tau, Eigen::Vector3d* jerk) const {
  // a = a_in + (c0 + c1 x) e^(-x/T): the critically damped response from (a0, j0), and its
  // integrals in closed form.
  const double x = tau - s.t0;
  const double T = 0.5 * options_.response_s, Ty = options_.yaw_response_s;
  const double E = std::exp(-x / T), ey = std::exp(-x / Ty);
  const Eigen::Vector3d c0 = s.a0 - s.a_in, c1 = s.j0 + c0 / T;
  const double I0 = T * (1.0 - E), I1 = T * T * (1.0 - E) - T * x * E;
  const double J0 = T * x - T * I0, J1 = T * T * x - T * T * I0 - T * I1;
  PathPoint q;
  q.a = s.a_in + (c0 + c1 * x) * E;
  q.v = s.v0 + s.a_in * x + c0 * I0 + c1 * I1;
  q.p = s.p0 + s.v0 * x + s.a_in * (0.5 * x * x) + c0 * J0 + c1 * J1;
  q.yaw = s.yaw0 + s.r_in * x + (s.r0 - s.r_in) * Ty * (1.0 - ey);
  if (jerk) *jerk = c1 * E - (c0 + c1 * x) * (E / T);
  return q;
}

PathPoint VehicleFlight::path(double tau) const {
  if (tau <= 0.0 || history_.empty()) {  // at rest at the start until the first step
    PathPoint q;
    q.p = start_.head<3>();
    q.yaw = start_[3];
    return q;
  }
  const double h = options_.control_period_s;
  const int64_t k = static_cast<int64_t>(std::floor(tau / h)) - first_step_;
  if (k < 0) throw std::out_of_range("VehicleFlight: time before the kept history");
  return evaluate(history_[std::min(static_cast<size_t>(k), history_.size() - 1)], tau);
}

MotionState VehicleFlight::state(double t) const {
  MotionState s = Flight::state(t);
  if (t < 0.0 || history_.empty()) return s;  // at rest
  const int64_t k = static_cast<int64_t>(std::floor(t / options_.control_period_s)) - first_step_;
  const Segment& seg = history_[std::min(static_cast<size_t>(std::max<int64_t>(k, 0)), history_.size() - 1)];
  s.omega_body = angular_rate(s.T_world_body.linear(), t, [&](double x) {
    const PathPoint q = evaluate(seg, x);
    return flat_attitude(q.a, q.yaw);
  });
  return s;
}

void VehicleFlight::step(const ControlOutput& input) {
  const VehicleOptions& o = options_;
  Segment s;
  s.t0 = end_s_;
  if (history_.empty()) {
    s.p0 = start_.head<3>();
    s.v0 = s.a0 = s.j0 = Eigen::Vector3d::Zero();
    s.yaw0 = start_[3];
    s.r0 = 0.0;
  } else {
    const Segment& last = history_.back();
    const PathPoint q = evaluate(last, end_s_, &s.j0);
    s.p0 = q.p, s.v0 = q.v, s.a0 = q.a, s.yaw0 = q.yaw;
    s.r0 = last.r_in + (last.r0 - last.r_in) * std::exp(-(end_s_ - last.t0) / o.yaw_response_s);
  }
  // Wind: an Ornstein-Uhlenbeck acceleration, weaker vertically (the thrust loop is stiffer).
  const double phi = std::exp(-o.control_period_s / o.wind_time_s);
  const double kick = o.wind_sigma_m_s2 * std::sqrt(1.0 - phi * phi);
  for (int i = 0; i < 3; ++i) wind_[i] = phi * wind_[i] + kick * (i == 2 ? 0.5 : 1.0) * wind_rng_.normal();
  s.a_in = input.accel + wind_;
  s.r_in = input.yaw_rate;
  history_.push_back(s);
  // Segment n starts at exactly n h, so finding a segment is an index.
  end_s_ = static_cast<double>(first_step_ + static_cast<int64_t>(history_.size())) * o.control_period_s;
  while (history_.size() > 2 && end_s_ - history_.front().t0 > o.history_s) {
    history_.pop_front();
    ++first_step_;
  }
}

VehicleLoop::VehicleLoop(VehicleFlight& vehicle, double lookahead_s)
    : vehicle_(vehicle), lookahead_s_(lookahead_s) {}

void VehicleLoop::set_command(const VehicleCommand& command) {
  command_ = command;
  latch_hold_ = command.mode == VehicleCommand::kHold;
  commanded_ = true;
}

void VehicleLoop::estimate_source_changed() {
  if (!commanded_) latch_hold_ = true;
}

void VehicleLoop::advance_to(double t_s, const VehicleEstimate& estimate) {
  if (latch_hold_) {
    // "Stop and hold the current position": where the vehicle believes it is now.
    command_.mode = VehicleCommand::kPosition;
    command_.position = estimate.p;
    command_.yaw = estimate.yaw;
    command_.velocity.setZero();
    command_.yaw_rate = 0.0;
    latch_hold_ = false;
  }
  while (vehicle_.end_s() < t_s + lookahead_s_) vehicle_.step(control(command_, estimate, vehicle_.options()));
}

}  // namespace kestrel::sim
