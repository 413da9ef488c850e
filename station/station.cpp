#include "station/station.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "station/wire.h"

namespace kestrel::station {
namespace {

// Whether `period_s` of sensor time has passed since `last` (a utime going backwards, a
// restarted replay, counts as due).
bool due(const std::optional<int64_t>& last, int64_t utime, double period_s) {
  return !last || utime < *last || static_cast<double>(utime - *last) >= period_s * 1e6;
}

}  // namespace

void StationOptions::validate() const {
  const auto positive = [](double v, const char* name) {
    if (!(v > 0.0) || !std::isfinite(v)) throw std::invalid_argument(std::string(name) + " must be > 0");
  };
  positive(state_period_s, "state period");
  positive(slow_period_s, "slow period");
  positive(path_step_m, "path step");
  if (path_max_points < 2) throw std::invalid_argument("path max points must be >= 2");
  if (!(goal.clearance_m >= 0.0) || goal.clearance_m > 2.0)
    throw std::invalid_argument("goal clearance must be 0..2 m");
}

std::string json_text(const nlohmann::json& update) {
  return update.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
}

Station::Station(const StationOptions& options, UpdateHub& hub, int64_t first_request_id)
    : options_(options),
      hub_(hub),
      next_request_id_(first_request_id),
      path_(options.path_step_m, options.path_max_points),
      truth_path_(options.path_step_m, options.path_max_points),
      previews_(options.preview) {
  options_.validate();
}

void Station::post_json(const std::string& kind, const nlohmann::json& update) {
  hub_.post(kind, Outgoing{false, json_text(update)});
}

void Station::notice(UpdateHub::ClientId client, bool ok, const std::string& text) {
  hub_.post_to(client, "notice", Outgoing{false, json_text({{"kind", "notice"}, {"ok", ok}, {"text", text}})});
}

void Station::on_state(const kestrel::state_t& m, const char* channel) {
  const nlohmann::json u = state_update(m, channel);  // throws before anything changes
  latest_utime_ = std::max(latest_utime_, m.utime);
  const bool usable = m.status == kestrel::state_t::STATUS_OK || m.status == kestrel::state_t::STATUS_DEGRADED;
  if (usable) path_.add(Eigen::Vector3d(u["p"][0].get<double>(), u["p"][1].get<double>(), u["p"][2].get<double>()));
  if (due(last_state_utime_, m.utime, options_.state_period_s)) {
    post_json("state", u);
    last_state_utime_ = m.utime;
  }
  if (due(last_path_utime_, m.utime, options_.slow_period_s) && path_.added() != path_posted_) {
    post_json("path", path_.to_json("path"));
    last_path_utime_ = m.utime;
    path_posted_ = path_.added();
  }
}

void Station::on_truth(const kestrel::ground_truth_t& m, const char* channel) {
  const nlohmann::json u = truth_update(m, channel);
  latest_utime_ = std::max(latest_utime_, m.utime);
  truth_path_.add(Eigen::Vector3d(u["p"][0].get<double>(), u["p"][1].get<double>(), u["p"][2].get<double>()));
  if (due(last_truth_utime_, m.utime, options_.slow_period_s)) {
    post_json("truth_pose", u);
    if (truth_path_.added() != truth_path_posted_) post_json("truth_path", truth_path_.to_json("truth_path"));
    truth_path_posted_ = truth_path_.added();
    last_truth_utime_ = m.utime;
  }
}

void Station::on_graph(const kestrel::slam_graph_t& m, const char* channel) {
  post_json("graph", graph_update(m, channel));
}

namespace {
bool same_plan(const kestrel::plan_t& plan, const kestrel::plan_covariance_t& covariance) {
  return plan.utime == covariance.utime && plan.request_id == covariance.request_id;
}
}  // namespace

void Station::on_plan(const kestrel::plan_t& m, const char* channel) {
  const bool matched = plan_covariance_ && same_plan(m, *plan_covariance_);
  post_json("plan", plan_update(m, channel, matched ? &*plan_covariance_ : nullptr));
  plan_ = m;
}

void Station::on_plan_covariance(const kestrel::plan_covariance_t& m, const char* channel) {
  if (plan_ && same_plan(*plan_, m)) post_json("plan", plan_update(*plan_, channel, &m));
  plan_covariance_ = m;
}

void Station::on_map(const kestrel::octomap_t& m, const char* channel) {
  auto cells = std::make_shared<const CellSet>(cells_of_message(m, channel));
  latest_utime_ = std::max(latest_utime_, m.utime);
  // The mapper sends an unchanged map again each period for late listeners: the page
  // already has it, and the snapshot need not change.
  if (map_ && map_->revision == cells->revision && map_->ids == cells->ids) return;
  map_ = cells;
  hub_.post_map(map_);
  post_json("map_info", {{"kind", "map_info"},
                         {"revision", m.revision},
                         {"utime", m.utime},
                         {"resolution", map_->resolution_m},
                         {"cells", map_->size()},
                         {"bounds", map_->known_bounds.isEmpty()
                                        ? nlohmann::json(nullptr)
                                        : nlohmann::json::array({map_->known_bounds.min().x(), map_->known_bounds.min().y(),
                                                                 map_->known_bounds.min().z(), map_->known_bounds.max().x(),
                                                                 map_->known_bounds.max().y(), map_->known_bounds.max().z()})}});
}

void Station::on_frame(const kestrel::rgbd_frame_t& m, const char* channel) {
  const std::optional<Preview> p = previews_.on_frame(m, channel);
  if (!p) return;
  if (!p->colour_jpeg.empty()) hub_.post("colour", Outgoing{true, encode_image(BinaryKind::kColour, ImageFormat::kJpeg, p->colour_jpeg)});
  if (!p->depth_jpeg.empty()) hub_.post("depth", Outgoing{true, encode_image(BinaryKind::kDepth, ImageFormat::kJpeg, p->depth_jpeg)});
}

void Station::on_status(const kestrel::process_status_t& m, double now_s) { health_.on_status(m, now_s); }

void Station::on_playback(const kestrel::playback_status_t& m, const char* channel) {
  const nlohmann::json u = playback_update(m, channel);  // throws before anything changes
  if (playback_ && m.seeks != playback_->seeks) reset();
  playback_ = m;
  post_json("playback", u);
}

void Station::post_periodic(double now_s) {
  post_json("rates", rates_.snapshot(now_s));
  post_json("health", health_.to_json(now_s));
}

CommandResult Station::on_command(UpdateHub::ClientId client, std::string_view text) {
  CommandResult r;
  try {
    const Command c = parse_command(text, options_.token);
    if (const auto* p = std::get_if<PlaybackCommand>(&c)) {
      if (!playback_) {
        r.notice = "no replay to control: the transport is for `kestrel replay LOG --control`";
      } else {
        r.playback = playback_command(*p, *playback_, next_request_id_++, r.notice);
        r.ok = r.notice.empty();
        if (!r.ok) r.playback.reset();
        char what[64] = "play";
        if (p->command == kestrel::playback_command_t::COMMAND_PAUSE) std::snprintf(what, sizeof what, "pause");
        if (p->command == kestrel::playback_command_t::COMMAND_SEEK) std::snprintf(what, sizeof what, "seek to %.1f s", p->seek_s);
        if (p->command == kestrel::playback_command_t::COMMAND_SPEED) std::snprintf(what, sizeof what, "speed %gx", p->speed);
        if (r.ok) r.notice = std::string(what) + " sent to the replay";
      }
    } else if (std::holds_alternative<HoldCommand>(c)) {
      r.hold = hold_plan(next_request_id_++, latest_utime_);
      r.ok = true;
      r.notice = "hold sent (PLAN without a path: the follower holds where the vehicle is)";
    } else {
      const GoalCommand& g = std::get<GoalCommand>(c);
      r.notice = check_goal(g, map_.get(), options_.goal);
      if (r.notice.empty()) {
        r.request = plan_request(g, next_request_id_++, latest_utime_);
        r.ok = true;
        nlohmann::json sent{{"kind", "notice"}, {"ok", true}, {"request_id", r.request->request_id},
                            {"goal", {g.goal[0], g.goal[1], g.goal[2], g.goal[3]}}};
        char buf[160];
        std::snprintf(buf, sizeof buf, "PLAN_REQUEST %lld sent: goal (%.2f, %.2f, %.2f), yaw %.2f",
                      static_cast<long long>(r.request->request_id), g.goal[0], g.goal[1], g.goal[2], g.goal[3]);
        r.notice = buf;
        sent["text"] = r.notice;
        hub_.post_to(client, "notice", Outgoing{false, json_text(sent)});
        return r;
      }
    }
  } catch (const CommandError& e) {
    r.notice = e.what();
  }
  notice(client, r.ok, r.notice);
  return r;
}

void Station::reset() {
  map_.reset();
  hub_.post_map(nullptr);
  path_.clear();
  truth_path_.clear();
  previews_.reset();
  last_state_utime_.reset();
  last_path_utime_.reset();
  last_truth_utime_.reset();
  plan_.reset();
  plan_covariance_.reset();
  path_posted_ = truth_path_posted_ = -1;
  latest_utime_ = 0;
  post_json("path", path_.to_json("path"));
  post_json("truth_path", truth_path_.to_json("truth_path"));
  post_json("graph", {{"kind", "graph"}, {"revision", -1}, {"keyframes", nlohmann::json::array()},
                      {"odometry", nlohmann::json::array()}, {"loops", nlohmann::json::array()}});
  post_json("plan", {{"kind", "plan"}, {"request_id", -1}, {"status", -1}, {"status_name", ""}, {"message", ""},
                     {"length", 0.0}, {"waypoints", nlohmann::json::array()}, {"sigma", nlohmann::json::array()}});
}

}  // namespace kestrel::station
