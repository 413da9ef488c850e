#include "mapper/mapper.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/error.h"
#include "common/geometry/se3.h"
#include "common/numbers.h"
#include "mapper/scan.h"

namespace kestrel::mapper {

namespace {

bool moved(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double metres, double degrees) {
  return se3::translation_distance(a, b) > metres || se3::rotation_distance(a, b) > degrees * kDegree;
}

// A keyframe of a SLAM graph as the store keeps it, with its decimated frame.
StoredKeyframe stored(const GraphKeyframe& g, RgbdFrame decimated) {
  StoredKeyframe kf;
  kf.id = g.id;
  kf.utime = g.utime;
  kf.T_world_camera = g.T_world_camera;
  kf.T_camera_depth = g.T_camera_depth;
  kf.frame = std::move(decimated);
  return kf;
}

}  // namespace

void MapperOptions::validate() const {
  map.validate();
  scan.validate();
  keyframes.validate();
  auto positive = [](double v, const char* name) {
    if (!(std::isfinite(v) && v > 0.0)) throw std::invalid_argument(std::string(name) + ": must be > 0");
  };
  auto non_negative = [](double v, const char* name) {
    if (!(std::isfinite(v) && v >= 0.0)) throw std::invalid_argument(std::string(name) + ": must be >= 0");
  };
  non_negative(keyframe_translation_m, "keyframe-translation");
  non_negative(keyframe_rotation_deg, "keyframe-rotation");
  non_negative(rebuild_translation_m, "rebuild-translation");
  non_negative(rebuild_rotation_deg, "rebuild-rotation");
  non_negative(rebuild_interval_s, "rebuild-interval");
  positive(frame_buffer_s, "frame-buffer");
  if (max_pinned_frames < 0) throw std::invalid_argument("max-pinned-frames: must be >= 0");
  if (checkpoint_every < 0) throw std::invalid_argument("checkpoint-every: must be >= 0");
  non_negative(checkpoint_megabytes, "checkpoint-megabytes");
}

Mapper::Mapper(const MapperOptions& options)
    : options_((options.validate(), options)),
      integrator_(options.map.resolution_m, options.scan),
      map_(options.map),
      keyframes_(options.keyframes) {}

void Mapper::integrate(const RgbdFrame& decimated, const Eigen::Isometry3d& T_world_camera,
                       int64_t utime, const char* what) {
  ScanOptions at_full = options_.scan;
  at_full.stride = 1;  // already decimated
  make_scan(decimated, T_world_camera, at_full, what, scan_);
  integrator_.compute(scan_, update_);
  map_.integrate(update_, utime);
  ++frames_inserted_;
}

void Mapper::integrate_keyframe(const StoredKeyframe& kf) {
  integrate(kf.frame, kf.T_world_depth(), kf.utime, "keyframe");
  if (!map_is_sequence_) return;
  sequence_.emplace_back(kf.id, kf.T_world_camera);
  maybe_checkpoint();
}

void Mapper::maybe_checkpoint() {
  const size_t every = static_cast<size_t>(options_.checkpoint_every);
  if (every == 0 || sequence_.size() % every != 0) return;
  if (!checkpoints_.empty() && checkpoints_.back().keyframes.size() >= sequence_.size()) return;
  checkpoints_.push_back({sequence_, map_});
  const double budget = options_.checkpoint_megabytes * 1e6;
  // Over budget: every other checkpoint goes (the spacing doubles), the newest stays.
  while (checkpoints_.size() > 1 && static_cast<double>(checkpoint_bytes()) > budget) {
    std::vector<Checkpoint> kept;
    for (size_t i = checkpoints_.size() % 2; i < checkpoints_.size(); i += 2) kept.push_back(std::move(checkpoints_[i]));
    checkpoints_ = std::move(kept);
  }
  if (static_cast<double>(checkpoint_bytes()) > budget) checkpoints_.clear();
}

size_t Mapper::checkpoint_bytes() const {
  size_t bytes = 0;
  for (const Checkpoint& c : checkpoints_) bytes += c.map.memory_bytes() + c.keyframes.size() * sizeof(Placed);
  return bytes;
}

const ScanUpdate& Mapper::insert(const RgbdFrame& frame, const Eigen::Isometry3d& T_world_camera,
                                 const char* what) {
  frame.validate(what);
  if (frame.depth_mm.empty()) throw InputError(std::string(what) + ": frame has no depth image");
  map_is_sequence_ = false;  // the map now holds a frame no rebuild inserts
  // The rays are built straight from the full-size depth image (each picked pixel read once);
  // the decimated frame is made only for a keyframe, with colour (the PLY export).
  const int64_t utime = frame.depth_utime != 0 ? frame.depth_utime : frame.utime;
  make_decimated_scan(frame, T_world_camera, options_.scan, what, scan_);
  integrator_.compute(scan_, update_);
  map_.integrate(update_, utime);
  ++frames_inserted_;
  if (!have_last_keyframe_ || moved(last_keyframe_pose_, T_world_camera,
                                    options_.keyframe_translation_m, options_.keyframe_rotation_deg)) {
    StoredKeyframe kf;
    kf.id = next_keyframe_id_++;
    kf.utime = utime;
    kf.T_world_camera = T_world_camera;
    kf.frame = decimate(frame, options_.scan.stride);
    keyframes_.add(std::move(kf));
    last_keyframe_pose_ = T_world_camera;
    have_last_keyframe_ = true;
  }
  return update_;
}

void Mapper::buffer_frame(const RgbdFrame& frame, const char* what, ColourSource colour) {
  frame.validate(what);
  if (frame.depth_mm.empty()) throw InputError(std::string(what) + ": frame has no depth image");
  if (colour && !frame.rgb.empty()) throw std::invalid_argument("Mapper::buffer_frame: colour given twice");
  if (!buffer_.empty() && frame.utime <= buffer_.back().decimated.utime) {
    throw InputError(std::string(what) + ": frame utime " + std::to_string(frame.utime) +
                     " is not after the previous frame's");
  }
  std::string source = colour ? std::string(what) : std::string();
  buffer_.push_back(Buffered{decimate(frame, options_.scan.stride), std::move(colour), frame.camera, std::move(source)});
  const int64_t keep_us = static_cast<int64_t>(options_.frame_buffer_s * 1e6);
  while (!buffer_.empty() && buffer_.front().decimated.utime < frame.utime - keep_us) buffer_.pop_front();
}

const RgbdFrame* Mapper::buffered(int64_t utime) const {
  auto it = std::lower_bound(buffer_.begin(), buffer_.end(), utime,
                             [](const Buffered& b, int64_t t) { return b.decimated.utime < t; });
  if (it != buffer_.end() && it->decimated.utime == utime) {
    if (it->colour) {
      const ColourSource colour = std::move(it->colour);
      it->colour = nullptr;
      // Whatever fails (a corrupt image, or the decoder itself), the frame keeps its depth and
      // goes on: a graph half applied would leave the map and its journal apart.
      try {
        const cv::Mat rgb = colour();
        if (rgb.type() != CV_8UC3 || rgb.cols != it->full_camera.width || rgb.rows != it->full_camera.height)
          throw InputError(it->what + ": the colour image is not the camera's size");
        it->decimated.rgb = decimate_colour(rgb, it->full_camera, options_.scan.stride);
      } catch (const std::exception& e) {
        ++colour_lost_;
        colour_lost_reason_ = e.what();
      }
    }
    return &it->decimated;
  }
  const auto pinned = pinned_.find(utime);
  return pinned != pinned_.end() ? &pinned->second : nullptr;
}

Mapper::Pin Mapper::pin(int64_t utime) {
  if (pinned_.count(utime) != 0) return Pin::kAlready;
  const RgbdFrame* frame = buffered(utime);
  if (frame == nullptr) return Pin::kGone;
  return hold_pinned(RgbdFrame(*frame));
}

Mapper::Pin Mapper::hold_pinned(RgbdFrame frame) {
  const int64_t utime = frame.utime;
  pinned_.emplace(utime, std::move(frame));
  while (static_cast<int>(pinned_.size()) > options_.max_pinned_frames) pinned_.erase(pinned_.begin());
  return pinned_.count(utime) != 0 ? Pin::kPinned : Pin::kGone;  // the oldest itself may go
}

std::vector<const RgbdFrame*> Mapper::pinned_frames() const {
  std::vector<const RgbdFrame*> frames;
  frames.reserve(pinned_.size());
  for (const auto& [utime, frame] : pinned_) frames.push_back(&frame);
  return frames;
}

Mapper::Pin Mapper::restore_pinned(RgbdFrame decimated) {
  decimated.validate("restored pinned frame");
  if (pinned_.count(decimated.utime) != 0) return Pin::kAlready;
  return hold_pinned(std::move(decimated));
}

void Mapper::keep_pinned(const std::set<int64_t>& utimes) {
  for (auto it = pinned_.begin(); it != pinned_.end();) it = utimes.count(it->first) != 0 ? std::next(it) : pinned_.erase(it);
}

std::vector<int64_t> Mapper::move_stored(const std::vector<GraphKeyframe>& graph,
                                         std::vector<GraphKeyframe>* fresh) {
  std::vector<int64_t> moved_ids;
  for (const GraphKeyframe& g : graph) {
    if (const StoredKeyframe* kf = keyframes_.find(g.id)) {
      if (moved(kf->T_world_camera, g.T_world_camera, options_.rebuild_translation_m,
                options_.rebuild_rotation_deg)) {
        keyframes_.set_pose(g.id, g.T_world_camera);
        moved_ids.push_back(g.id);
      }
    } else if (fresh != nullptr) {
      fresh->push_back(g);
    }
  }
  return moved_ids;
}

void Mapper::restore_keyframe(const GraphKeyframe& keyframe, RgbdFrame decimated) {
  decimated.validate("restored keyframe");
  keyframes_.add(stored(keyframe, std::move(decimated)));
  map_is_sequence_ = false;  // the map does not hold it until the rebuild
}

size_t Mapper::restore_poses(const std::vector<GraphKeyframe>& keyframes) {
  return move_stored(keyframes, nullptr).size();
}

GraphResult Mapper::apply_graph(const std::vector<GraphKeyframe>& graph) {
  GraphResult result;
  std::vector<GraphKeyframe> fresh;
  int64_t newest = 0;
  for (const GraphKeyframe& g : graph) newest = std::max(newest, g.utime);
  result.moved = move_stored(graph, &fresh);
  std::sort(fresh.begin(), fresh.end(),
            [](const GraphKeyframe& a, const GraphKeyframe& b) { return a.utime < b.utime; });
  if (!result.moved.empty()) rebuild_pending_ = true;
  const bool may_rebuild =
      last_rebuild_utime_ < 0 ||
      1e-6 * static_cast<double>(newest - last_rebuild_utime_) >= options_.rebuild_interval_s;

  for (const GraphKeyframe& g : fresh) {
    const RgbdFrame* frame = buffered(g.utime);
    if (frame == nullptr) {
      ++result.missing;
      continue;
    }
    const bool was_pinned = pinned_.count(g.utime) != 0;
    // Inserted now unless the whole map is about to be rebuilt anyway.
    store(stored(g, *frame), !(rebuild_pending_ && may_rebuild));
    if (was_pinned) {  // stored (a copy): no longer needed; `frame` is not used after this
      pinned_.erase(g.utime);
      ++result.from_pinned;
    }
    result.inserted.push_back(g.id);
  }
  if (rebuild_pending_ && may_rebuild) {
    result.reinserted = rebuild();
    last_rebuild_utime_ = newest;
    result.rebuilt = true;
    result.rebuild_keyframes = keyframes_.size();
  }
  return result;
}

void Mapper::store(StoredKeyframe kf, bool insert_now) {
  // A new keyframe goes last in the store's order, as into the live map. One that replaces a
  // stored keyframe does too, but the map also holds its earlier insertion, which no rebuild
  // repeats: the live map is no longer a checkpointable sequence.
  if (keyframes_.contains(kf.id)) map_is_sequence_ = false;
  if (insert_now) integrate_keyframe(kf);
  keyframes_.add(std::move(kf));
}

int64_t Mapper::next_located_id() const {
  const std::optional<int64_t> newest = keyframes_.max_id();
  return newest && *newest >= kFirstLocatedId ? *newest + 1 : kFirstLocatedId;
}

Mapper::Located Mapper::add_located(const GraphKeyframe& located) {
  const RgbdFrame* frame = buffered(located.utime);
  if (frame == nullptr) return Located::kNotBuffered;
  store(stored(located, *frame), true);
  return Located::kInserted;
}

size_t Mapper::rebuild() { return rebuild_from(true); }

size_t Mapper::rebuild_from_scratch() { return rebuild_from(false); }

size_t Mapper::rebuild_from(bool use_checkpoints) {
  const std::vector<const StoredKeyframe*> order = keyframes_.in_stored_order();
  // The newest checkpoint holding exactly the first keyframes of `order` at their current
  // poses (a pose that moved by less than the rebuild threshold was not updated, so equality
  // is exact); the ones after it are stale.
  size_t valid = 0;
  for (; valid < checkpoints_.size(); ++valid) {
    const std::vector<Placed>& held = checkpoints_[valid].keyframes;
    bool same = held.size() <= order.size();
    for (size_t i = 0; same && i < held.size(); ++i) {
      same = held[i].first == order[i]->id &&
             held[i].second.matrix() == order[i]->T_world_camera.matrix();
    }
    if (!same) break;
  }
  checkpoints_.resize(valid);
  size_t start = 0;
  if (use_checkpoints && valid > 0) {
    map_ = checkpoints_.back().map;
    sequence_ = checkpoints_.back().keyframes;
    start = sequence_.size();
  } else {
    map_.clear();
    sequence_.clear();
  }
  map_is_sequence_ = true;
  for (size_t i = start; i < order.size(); ++i) integrate_keyframe(*order[i]);
  rebuild_pending_ = false;
  ++rebuilds_;
  return order.size() - start;
}

void Mapper::reset() {
  map_.clear();
  checkpoints_.clear();
  sequence_.clear();
  map_is_sequence_ = true;
  keyframes_.clear();
  buffer_.clear();
  pinned_.clear();
  have_last_keyframe_ = false;
  next_keyframe_id_ = 0;
  last_rebuild_utime_ = -1;
  rebuild_pending_ = false;
  frames_inserted_ = 0;
}

}  // namespace kestrel::mapper
