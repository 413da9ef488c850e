#include "station/updates.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "common/error.h"
#include "common/transport/convert.h"

namespace kestrel::station {
namespace {

using nlohmann::json;

json vec3(const Eigen::Vector3d& v) { return json::array({v.x(), v.y(), v.z()}); }
// Millimetres: what a drawn path or keyframe needs; JSON of a long path is then about a third
// of full precision's size.
double mm(double v) { return std::round(v * 1e3) / 1e3; }
json vec3_mm(const Eigen::Vector3d& v) { return json::array({mm(v.x()), mm(v.y()), mm(v.z())}); }
json quat(const Eigen::Quaterniond& q) { return json::array({q.w(), q.x(), q.y(), q.z()}); }

// The 1-sigma ellipsoid of a 3x3 covariance: its semi-axes and the rotation whose columns are
// their directions (a proper rotation, so the page can use it as an orientation). Empty for a
// covariance that is not finite and symmetric; tiny negative eigenvalues (round-off) count as 0.
json ellipsoid(const Eigen::Matrix3d& cov) {
  if (!cov.allFinite() || !cov.isApprox(cov.transpose(), 1e-9) ) return nullptr;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  if (eig.info() != Eigen::Success) return nullptr;
  Eigen::Matrix3d axes = eig.eigenvectors();
  if (axes.determinant() < 0) axes.col(2) = -axes.col(2);
  const Eigen::Vector3d radii = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();
  return json{{"radii", vec3(radii)}, {"q", quat(Eigen::Quaterniond(axes).normalized())}};
}

double yaw_of(const Eigen::Matrix3d& R) { return std::atan2(R(1, 0), R(0, 0)); }

}  // namespace

json state_update(const kestrel::state_t& m, const char* channel) {
  const Eigen::Isometry3d T_world_body = transport::from_message(m.T_world_body, channel);
  json u{{"kind", "state"},
         {"utime", m.utime},
         {"status", m.status},
         {"p", vec3(T_world_body.translation())},
         {"q", quat(Eigen::Quaterniond(T_world_body.linear()))},
         {"yaw", yaw_of(T_world_body.linear())}};
  const bool sized = m.cov_dim >= 3 && static_cast<size_t>(m.cov_dim) == m.covariance.size() &&
                     std::all_of(m.covariance.begin(), m.covariance.end(),
                                 [&](const std::vector<double>& row) { return row.size() == static_cast<size_t>(m.cov_dim); });
  if (sized) {
    Eigen::Matrix3d P;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) P(r, c) = m.covariance[static_cast<size_t>(r)][static_cast<size_t>(c)];
    if (json e = ellipsoid(P); !e.is_null()) u["cov"] = std::move(e);
  }
  return u;
}

json truth_update(const kestrel::ground_truth_t& m, const char* channel) {
  const Eigen::Isometry3d T_world_frame = transport::from_message(m.T_world_frame, channel);
  return json{{"kind", "truth_pose"},
              {"utime", m.utime},
              {"frame", m.frame == kestrel::ground_truth_t::FRAME_CAMERA ? "camera" : "body"},
              {"p", vec3(T_world_frame.translation())},
              {"q", quat(Eigen::Quaterniond(T_world_frame.linear()))}};
}

json graph_update(const kestrel::slam_graph_t& m, const char* channel) {
  if (m.num_keyframes != static_cast<int32_t>(m.keyframes.size()) || m.num_edges != static_cast<int32_t>(m.edges.size()))
    throw InputError(std::string(channel) + ": counts disagree with the arrays");
  json keyframes = json::array(), odometry = json::array(), loops = json::array();
  std::unordered_map<int64_t, size_t> index;
  for (const auto& kf : m.keyframes) {
    const Eigen::Isometry3d T_world_camera = transport::from_message(kf.T_world_camera, channel);
    index.emplace(kf.id, keyframes.size());
    keyframes.push_back(vec3_mm(T_world_camera.translation()));
  }
  for (const auto& e : m.edges) {
    const auto a = index.find(e.from_id), b = index.find(e.to_id);
    if (a == index.end() || b == index.end()) continue;
    (e.kind == kestrel::slam_edge_t::KIND_LOOP_CLOSURE ? loops : odometry).push_back(json::array({a->second, b->second}));
  }
  return json{{"kind", "graph"}, {"revision", m.revision}, {"keyframes", std::move(keyframes)},
              {"odometry", std::move(odometry)}, {"loops", std::move(loops)}};
}

json plan_update(const kestrel::plan_t& m, const char* channel, const kestrel::plan_covariance_t* covariance) {
  const std::string where = std::string(channel) + ": plan " + std::to_string(m.request_id) + ": ";
  if (m.num_waypoints < 0 || static_cast<size_t>(m.num_waypoints) != m.waypoints.size() ||
      m.waypoints.size() != m.covariance_trace.size())
    throw InputError(where + "num_waypoints disagrees with the arrays");
  json waypoints = json::array(), sigma = json::array();
  for (size_t i = 0; i < m.waypoints.size(); ++i) {
    const auto& w = m.waypoints[i];
    if (!std::isfinite(w[0]) || !std::isfinite(w[1]) || !std::isfinite(w[2]) || !std::isfinite(w[3]))
      throw InputError(where + "waypoint " + std::to_string(i) + " is not finite");
    waypoints.push_back(json::array({w[0], w[1], w[2], w[3]}));
    const double trace = m.covariance_trace[i];
    sigma.push_back(std::isfinite(trace) && trace >= 0.0 ? std::sqrt(trace / 4.0) : 0.0);
  }
  json update{{"kind", "plan"},
              {"request_id", m.request_id},
              {"status", m.status},
              {"status_name", plan_status_name(m.status)},
              {"message", m.message},
              {"length", std::isfinite(m.length) ? m.length : 0.0},
              {"waypoints", std::move(waypoints)},
              {"sigma", std::move(sigma)}};
  if (!covariance) return update;
  if (covariance->utime != m.utime || covariance->request_id != m.request_id)
    throw InputError(where + "the covariance given is another plan's (" + std::to_string(covariance->request_id) + ")");
  if (covariance->num_waypoints != m.num_waypoints ||
      covariance->covariance.size() != static_cast<size_t>(std::max(covariance->num_waypoints, 0)))
    throw InputError(where + "PLAN_COVARIANCE has " + std::to_string(covariance->num_waypoints) + " waypoints, the plan " +
                     std::to_string(m.num_waypoints));
  json ellipses = json::array();
  for (size_t i = 0; i < covariance->covariance.size(); ++i) {
    const auto& c = covariance->covariance[i];  // row-major 4 x 4; the horizontal block is c[0], c[1], c[5]
    if (c.size() != 16) throw InputError(where + "covariance " + std::to_string(i) + " is not 4 x 4");
    const double xx = c[0], xy = 0.5 * (c[1] + c[4]), yy = c[5];
    if (!std::isfinite(xx) || !std::isfinite(xy) || !std::isfinite(yy))
      throw InputError(where + "covariance " + std::to_string(i) + " is not finite");
    // The eigen-decomposition of the symmetric 2 x 2 block, in closed form.
    const double mean = 0.5 * (xx + yy), half_gap = std::hypot(0.5 * (xx - yy), xy);
    const double major = std::sqrt(std::max(mean + half_gap, 0.0)), minor = std::sqrt(std::max(mean - half_gap, 0.0));
    ellipses.push_back(json::array({major, minor, 0.5 * std::atan2(2.0 * xy, xx - yy)}));
  }
  update["ellipses"] = std::move(ellipses);
  return update;
}

json playback_update(const kestrel::playback_status_t& m, const char* channel) {
  constexpr int64_t kYearUs = int64_t{366} * 24 * 3600 * 1'000'000;
  // Differences in double: the stamps come off the bus and may lie anywhere.
  const double length_us = static_cast<double>(m.end_utime) - static_cast<double>(m.start_utime);
  if (!(length_us >= 0.0 && length_us <= static_cast<double>(kYearUs)))
    throw InputError(std::string(channel) + ": the log's window ends before it starts or spans more than a year");
  if (!(m.speed > 0.0) || !std::isfinite(m.speed))
    throw InputError(std::string(channel) + ": the speed is not a positive number");
  const double t_us = std::clamp(static_cast<double>(m.utime) - static_cast<double>(m.start_utime), 0.0, length_us);
  return {{"kind", "playback"}, {"log", m.log_name},       {"t", 1e-6 * t_us},         {"length", 1e-6 * length_us},
          {"speed", m.speed},   {"paused", m.paused},      {"at_end", m.at_end},       {"seeks", m.seeks}};
}

PathTrace::PathTrace(double min_step_m, size_t max_points) : min_step_m_(min_step_m), max_points_(std::max<size_t>(max_points, 2)) {}

bool PathTrace::add(const Eigen::Vector3d& p) {
  if (!p.allFinite()) return false;
  if (!points_.empty() && (p - points_.back()).norm() < min_step_m_) return false;
  points_.push_back(p);
  ++added_;
  if (points_.size() > max_points_) {
    // Halve the resolution: keep every second point, and always the newest.
    std::vector<Eigen::Vector3d> kept;
    kept.reserve(points_.size() / 2 + 1);
    for (size_t i = 0; i + 1 < points_.size(); i += 2) kept.push_back(points_[i]);
    kept.push_back(points_.back());
    points_ = std::move(kept);
  }
  return true;
}

json PathTrace::to_json(const std::string& kind) const {
  json pts = json::array();
  for (const auto& p : points_) pts.push_back(vec3_mm(p));
  return json{{"kind", kind}, {"points", std::move(pts)}};
}

void HealthTable::on_status(const kestrel::process_status_t& m, double now_s) {
  if (rows_.size() >= kMaxProcesses && rows_.find(m.name) == rows_.end()) return;
  rows_[m.name] = Row{m, now_s};
}

std::vector<std::string> HealthTable::names() const {
  std::vector<std::string> out;
  for (const auto& [name, row] : rows_) out.push_back(name);
  return out;
}

json HealthTable::to_json(double now_s) const {
  json rows = json::array();
  for (const auto& [name, row] : rows_) {
    const auto& s = row.status;
    rows.push_back(json{{"name", name},
                        {"pid", s.pid},
                        {"state", s.state},
                        {"state_name", process_state_name(s.state)},
                        {"message", s.message},
                        {"in", s.messages_in},
                        {"out", s.messages_out},
                        {"rejected", s.messages_rejected},
                        {"age_s", std::max(0.0, now_s - row.heard_s)},
                        {"subscriptions", s.subscriptions},
                        {"publications", s.publications}});
  }
  return json{{"kind", "health"}, {"processes", std::move(rows)}};
}

void ChannelRates::on_message(const std::string& channel, size_t bytes) {
  auto it = counts_.find(channel);
  if (it == counts_.end()) {
    const std::string& key = counts_.size() < kMaxChannels ? channel : std::string("(other)");
    it = counts_.try_emplace(key).first;
  }
  ++it->second.messages;
  it->second.bytes += static_cast<int64_t>(bytes);
}

json ChannelRates::snapshot(double now_s) {
  if (since_s_ < 0.0) since_s_ = now_s;
  const double dt = now_s - since_s_;
  json rows = json::array();
  for (auto it = counts_.begin(); it != counts_.end();) {
    Count& c = it->second;
    if (c.messages == 0 && !c.seen_last_interval) {
      it = counts_.erase(it);
      continue;
    }
    rows.push_back(json{{"channel", it->first},
                        {"hz", dt > 0.0 ? static_cast<double>(c.messages) / dt : 0.0},
                        {"bytes_per_s", dt > 0.0 ? static_cast<double>(c.bytes) / dt : 0.0}});
    c.seen_last_interval = c.messages > 0;
    c.messages = c.bytes = 0;
    ++it;
  }
  since_s_ = now_s;
  return json{{"kind", "rates"}, {"interval_s", dt}, {"channels", std::move(rows)}};
}

std::string process_state_name(int8_t state) {
  switch (state) {
    case kestrel::process_status_t::STATE_STARTING: return "STARTING";
    case kestrel::process_status_t::STATE_RUNNING: return "RUNNING";
    case kestrel::process_status_t::STATE_DEGRADED: return "DEGRADED";
    case kestrel::process_status_t::STATE_STOPPING: return "STOPPING";
    case kestrel::process_status_t::STATE_FAILED: return "FAILED";
    default: return "UNKNOWN(" + std::to_string(state) + ")";
  }
}

std::string plan_status_name(int8_t status) {
  switch (status) {
    case kestrel::plan_t::STATUS_OK: return "OK";
    case kestrel::plan_t::STATUS_NO_PATH: return "NO_PATH";
    case kestrel::plan_t::STATUS_START_IN_COLLISION: return "START_IN_COLLISION";
    case kestrel::plan_t::STATUS_GOAL_IN_COLLISION: return "GOAL_IN_COLLISION";
    case kestrel::plan_t::STATUS_NO_MAP: return "NO_MAP";
    case kestrel::plan_t::STATUS_BAD_REQUEST: return "BAD_REQUEST";
    default: return "UNKNOWN(" + std::to_string(status) + ")";
  }
}

}  // namespace kestrel::station
