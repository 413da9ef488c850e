#include "mapper/map_node.h"

#include <set>

#include <algorithm>
#include <cmath>
#include <functional>
#include <stdexcept>
#include <string>

#include "common/error.h"
#include "common/transport/convert.h"
#include "common/transport/rgbd_codec.h"
#include "mapper/octree_io.h"

namespace kestrel::mapper {

namespace {
// The rebuilt map replaces the old one: the revision jumps to the next thousand, so a viewer
// can tell a rebuild from an increment.
constexpr int64_t kRebuildRevisionStep = 1000;
}  // namespace

void NodeOptions::validate() const {
  mapper.validate();
  if (!(std::isfinite(publish_period_s) && publish_period_s >= 0.0))
    throw std::invalid_argument("publish-period: must be >= 0");
  if (!(std::isfinite(max_pose_gap_s) && max_pose_gap_s > 0.0))
    throw std::invalid_argument("max-pose-gap: must be > 0");
  if (max_pending_frames < 1) throw std::invalid_argument("max-pending-frames: must be >= 1");
  // 0 would delete the journal a reset has just set aside: keeping none is not offered.
  if (journal_keep < 1) throw std::invalid_argument("journal-keep: must be >= 1");
  if (!(std::isfinite(journal_compact_mb) && journal_compact_mb > 0.0))
    throw std::invalid_argument("journal-compact-mb: must be > 0");
  if (!journal_path.empty() && pose_source != PoseSource::kSlamGraph)
    throw std::invalid_argument("journal: only with the slam pose source");
}

MapNode::MapNode(const NodeOptions& options)
    : options_((options.validate(), options)), mapper_(options.mapper) {
  if (options_.journal_path.empty()) return;
  const JournalContents journal = read_journal(options_.journal_path);
  journal_damage_ = journal.damage;
  const Restored restored = restore_journal(journal, mapper_, options_.journal_path);
  stats_.keyframes_restored = restored.keyframes;
  stats_.pinned_restored = restored.pinned;
  last_graph_revision_ = restored.last_revision;
  // A damaged journal is kept aside whole and continued as a fresh copy of what was read. If
  // that fails (a full disk is the usual cause of the damage), the restored map is kept and
  // mapping goes on without a journal, as after a failed write: the file stays as it was.
  try {
    journal_ = std::make_unique<JournalWriter>(options_.journal_path, journal, options_.journal_keep);
    journal_kept_aside_ = journal_->kept_aside();
    journal_pruned_ = journal_->pruned();
  } catch (const std::exception& e) {
    journal_error_ = e.what();
  }
}

void MapNode::journal(const std::function<void(JournalWriter&)>& write) {
  if (!journal_) return;
  try {
    write(*journal_);
  } catch (const std::exception& e) {
    // The map matters more than its copy: stop journalling (a later record after a lost one
    // would restore a different map) and map on.
    journal_error_ = e.what();
    journal_.reset();
  }
}

void MapNode::write_journal(const kestrel::slam_graph_t& msg, const GraphResult& result) {
  journal([&](JournalWriter& writer) {
    // In apply_graph's order: the keyframes the graph moved, if any (the others kept their
    // stored poses, and a restore moves a keyframe only where its pose differs by more than the
    // thresholds, as apply_graph did), then the new keyframes as the message gave them, so a
    // restore replays the same steps and ends with the same poses, bit for bit.
    if (!result.moved.empty()) {
      kestrel::slam_graph_t poses;  // no edges: a restore needs none
      poses.utime = msg.utime;
      poses.revision = msg.revision;
      for (const kestrel::slam_keyframe_t& k : msg.keyframes) {
        if (std::find(result.moved.begin(), result.moved.end(), k.id) != result.moved.end())
          poses.keyframes.push_back(k);
      }
      poses.num_keyframes = static_cast<int32_t>(poses.keyframes.size());
      poses.num_edges = 0;
      writer.graph(poses);
    }
    for (const int64_t id : result.inserted) {
      const auto k = std::find_if(msg.keyframes.begin(), msg.keyframes.end(),
                                  [&](const kestrel::slam_keyframe_t& m) { return m.id == id; });
      // (Over the keyframe budget, one stored by this graph may have gone already.)
      if (const StoredKeyframe* stored = mapper_.keyframes().find(id)) writer.keyframe(*k, stored->frame);
    }
  });
}

std::set<int64_t> MapNode::pinned_utimes() const {
  std::set<int64_t> utimes;
  for (const RgbdFrame* frame : mapper_.pinned_frames()) utimes.insert(frame->utime);
  return utimes;
}

void MapNode::journal_released_pins(const std::set<int64_t>& were_pinned) {
  const std::set<int64_t> pinned = pinned_utimes();
  std::vector<int64_t> released;
  for (const int64_t utime : were_pinned)
    if (pinned.count(utime) == 0) released.push_back(utime);
  if (!released.empty()) journal([&](JournalWriter& writer) { writer.released(released); });
}

void MapNode::compact_journal_if_due() {
  if (!journal_) return;
  const KeyframeStore& store = mapper_.keyframes();
  const double margin = options_.journal_compact_mb * 1e6;
  const double due = std::max(2.0 * static_cast<double>(store.bytes()) + margin, compact_retry_bytes_);
  if (static_cast<double>(journal_->bytes()) <= due) return;
  // In the order they were stored: a restore stores and bins them in this order again.
  std::vector<LiveKeyframe> live;
  live.reserve(store.size());
  for (const StoredKeyframe* k : store.in_stored_order()) live.push_back({k->id, &k->frame});
  try {
    journal_->compact(live, last_graph_revision_, mapper_.pinned_frames());
    journal_compaction_error_.clear();
  } catch (const std::exception& e) {
    // compact() is atomic: the old journal is whole and still appended to, so journalling goes
    // on (a full disk stops it at the next append, as always); tried again once the journal
    // has grown by another margin.
    journal_compaction_error_ = e.what();
    compact_retry_bytes_ = static_cast<double>(journal_->bytes()) + margin;
  }
}

void MapNode::reset() {
  if (options_.journal_is_map && !input_since_start_) return;  // the saved map is where this flight begins
  input_since_start_ = false;
  mapper_.reset();
  journal_kept_aside_.clear();
  journal_pruned_ = {};
  journal_compaction_error_.clear();
  compact_retry_bytes_ = 0.0;
  // The journal starts again with the map; the one it ends is kept, never emptied in place.
  journal([&](JournalWriter& writer) {
    writer.restart();
    journal_kept_aside_ = writer.kept_aside();
    journal_pruned_ = writer.pruned();
  });
  stats_ = {};
  last_frame_utime_ = 0;
  last_published_utime_ = -1;
  revision_ = 0;
  last_graph_revision_ = -1;
  last_map_.reset();
  last_map_frame_utime_ = 0;
  pending_.clear();
  poses_ = Trajectory();
}

MapNode::Health MapNode::health() const {
  if (journal_error_.empty()) return {};
  return {kestrel::process_status_t::STATE_DEGRADED, "journal stopped: " + journal_error_};
}

kestrel::octomap_t MapNode::map_message() {
  const VoxelMap& map = mapper_.map();
  kestrel::octomap_t msg;
  msg.utime = map.utime();
  msg.revision = ++revision_;
  msg.resolution = map.resolution();
  msg.format = options_.full_format ? kestrel::octomap_t::FORMAT_FULL : kestrel::octomap_t::FORMAT_BINARY;
  const auto bytes = encode_octree(map, options_.full_format ? OctreeFormat::kFull : OctreeFormat::kBinary);
  msg.data.assign(bytes.begin(), bytes.end());
  msg.size = static_cast<int32_t>(msg.data.size());
  last_published_utime_ = map.utime();
  ++stats_.published;
  last_map_ = msg;
  last_map_frame_utime_ = last_frame_utime_;
  return msg;
}

std::optional<kestrel::octomap_t> MapNode::maybe_publish(bool now) {
  const int64_t utime = mapper_.map().utime();
  if (mapper_.map().num_cells() == 0) return std::nullopt;
  const bool due = last_published_utime_ < 0 ||
                   1e-6 * static_cast<double>(utime - last_published_utime_) >= options_.publish_period_s;
  if (!now && !due) return std::nullopt;
  return map_message();
}

std::optional<kestrel::octomap_t> MapNode::repeat_map(int64_t frame_utime) {
  if (!last_map_ || 1e-6 * static_cast<double>(frame_utime - last_map_frame_utime_) < options_.publish_period_s)
    return std::nullopt;
  last_map_frame_utime_ = frame_utime;
  ++stats_.repeated;
  return last_map_;
}

std::optional<kestrel::octomap_t> MapNode::on_frame(const kestrel::rgbd_frame_t& msg, const char* channel) {
  input_since_start_ = true;
  // In SLAM mode a frame's colour is decoded only if a keyframe takes it (Mapper::buffer_frame).
  transport::RgbdDeferredColour decoded =
      options_.pose_source == PoseSource::kSlamGraph ? transport::decode_rgbd_deferring_colour(msg, channel)
                                                     : transport::RgbdDeferredColour{transport::decode_rgbd(msg, channel), {}};
  RgbdFrame& frame = decoded.frame;
  if (frame.depth_mm.empty()) throw InputError(std::string(channel) + ": frame has no depth image");
  if (stats_.frames > 0 && frame.utime <= last_frame_utime_) {
    throw InputError(std::string(channel) + ": frame utime " + std::to_string(frame.utime) +
                     " is not after the previous frame's " + std::to_string(last_frame_utime_));
  }
  last_frame_utime_ = frame.utime;
  ++stats_.frames;
  if (options_.pose_source == PoseSource::kSlamGraph) {
    mapper_.buffer_frame(frame, channel, std::move(decoded.colour));
    return repeat_map(frame.utime);
  }
  pending_.push_back(std::move(frame));
  while (static_cast<int>(pending_.size()) > options_.max_pending_frames) {
    pending_.pop_front();
    ++stats_.frames_without_pose;
  }
  insert_pending();
  return maybe_publish(false);
}

void MapNode::insert_pending() {
  if (poses_.empty()) return;
  const int64_t newest = poses_.poses().back().utime;
  const int64_t max_gap = static_cast<int64_t>(std::llround(options_.max_pose_gap_s * 1e6));
  while (!pending_.empty()) {
    const RgbdFrame& f = pending_.front();
    const int64_t t = f.depth_utime != 0 ? f.depth_utime : f.utime;
    if (t > newest) return;  // its pose has not arrived yet
    if (const auto T_world_body = poses_.at(t, max_gap)) {
      mapper_.insert(f, *T_world_body * f.T_body_camera, "CAMERA_RGBD");
      ++stats_.frames_inserted;
    } else {
      ++stats_.frames_without_pose;
    }
    pending_.pop_front();
  }
}

std::optional<kestrel::octomap_t> MapNode::on_ground_truth(const kestrel::ground_truth_t& msg,
                                                           const char* channel) {
  input_since_start_ = true;
  if (options_.pose_source != PoseSource::kGroundTruth) return std::nullopt;
  Eigen::Isometry3d T = transport::from_message(msg.T_world_frame, channel);
  // Frames are placed by T_world_body * T_body_camera; camera-frame truth (TUM) is turned into a
  // body pose for frames whose body is their camera, which is every TUM frame.
  if (msg.frame != kestrel::ground_truth_t::FRAME_BODY && msg.frame != kestrel::ground_truth_t::FRAME_CAMERA) {
    throw InputError(std::string(channel) + ": unknown frame " + std::to_string(msg.frame));
  }
  if (!poses_.empty() && msg.utime <= poses_.poses().back().utime) {
    throw InputError(std::string(channel) + ": utime " + std::to_string(msg.utime) +
                     " is not after the previous pose's");
  }
  if (poses_.size() >= 4000) {  // keep the last ~20 s at 100 Hz
    std::vector<StampedPose> recent(poses_.poses().end() - 2000, poses_.poses().end());
    poses_ = Trajectory(std::move(recent));
  }
  poses_.push_back(msg.utime, T);
  insert_pending();
  return maybe_publish(false);
}

std::optional<kestrel::octomap_t> MapNode::on_correction(const kestrel::slam_correction_t& msg,
                                                         const char* channel) {
  input_since_start_ = true;
  if (options_.pose_source != PoseSource::kSlamGraph || !options_.insert_located) return std::nullopt;
  const Eigen::Isometry3d T_world_body = transport::from_message(msg.T_world_body, channel);
  if (msg.utime <= 0) throw InputError(std::string(channel) + ": utime " + std::to_string(msg.utime) + " is not a time");
  // A keyframe's own correction (after an optimisation): the graph placed it. Told by id and
  // time together: a simulator's flights all start at the same utime.
  if (const StoredKeyframe* kf = mapper_.keyframes().find(msg.keyframe_id); kf != nullptr && kf->utime == msg.utime)
    return std::nullopt;
  // As a graph keyframe of an id no graph names: no graph moves it. Stored as the journal will
  // restore it (from this message).
  const RgbdFrame* frame = mapper_.buffered(msg.utime);
  kestrel::slam_keyframe_t k{};
  k.id = mapper_.next_located_id();
  k.utime = msg.utime;
  k.T_world_camera = transport::to_message(frame ? T_world_body * frame->T_body_camera : T_world_body);
  k.T_camera_depth = transport::to_message(Eigen::Isometry3d::Identity());
  switch (mapper_.add_located(to_graph_keyframe(k, channel))) {
    case Mapper::Located::kNotBuffered:
      ++stats_.located_missing;
      return std::nullopt;
    case Mapper::Located::kInserted:
      break;
  }
  ++stats_.located;
  ++stats_.frames_inserted;
  journal([&](JournalWriter& writer) {
    if (const StoredKeyframe* kf = mapper_.keyframes().find(k.id)) writer.keyframe(k, kf->frame);
  });
  compact_journal_if_due();
  return maybe_publish(false);
}

void MapNode::on_unplaced_graph(const kestrel::slam_graph_t& msg, const char* channel) {
  input_since_start_ = true;
  if (options_.pose_source != PoseSource::kSlamGraph) return;
  if (msg.num_keyframes != static_cast<int32_t>(msg.keyframes.size())) {
    throw InputError(std::string(channel) + ": num_keyframes does not match the keyframes sent");
  }
  std::set<int64_t> listed;
  for (const auto& k : msg.keyframes) listed.insert(k.utime);
  std::set<int64_t> were_pinned = pinned_utimes();
  mapper_.keep_pinned(listed);  // a keyframe no longer listed will not join (a SLAM restarted)
  for (const auto& k : msg.keyframes) {
    if (mapper_.keyframes().find(k.id) != nullptr) continue;  // already in the map
    if (mapper_.pin(k.utime) != Mapper::Pin::kPinned) continue;
    ++stats_.unplaced_pinned;
    were_pinned.insert(k.utime);  // (the bound may let it go again at once)
    // On disk too: a mapper restarted before the placement would otherwise have lost the frame.
    journal([&](JournalWriter& writer) { writer.pinned(*mapper_.buffered(k.utime)); });
  }
  journal_released_pins(were_pinned);
  compact_journal_if_due();
}

std::optional<kestrel::octomap_t> MapNode::on_graph(const kestrel::slam_graph_t& msg, const char* channel) {
  input_since_start_ = true;
  if (options_.pose_source != PoseSource::kSlamGraph) return std::nullopt;
  if (msg.revision < last_graph_revision_) {
    throw InputError(std::string(channel) + ": revision " + std::to_string(msg.revision) +
                     " is older than the previous " + std::to_string(last_graph_revision_));
  }
  if (msg.num_keyframes != static_cast<int32_t>(msg.keyframes.size())) {
    throw InputError(std::string(channel) + ": num_keyframes does not match the keyframes sent");
  }
  std::vector<GraphKeyframe> keyframes;
  keyframes.reserve(msg.keyframes.size());
  for (const auto& k : msg.keyframes) keyframes.push_back(to_graph_keyframe(k, channel));
  last_graph_revision_ = msg.revision;
  ++stats_.graphs;
  const std::set<int64_t> were_pinned = pinned_utimes();
  const GraphResult result = mapper_.apply_graph(keyframes);
  mapper_.keep_pinned({});  // placed: SLAM sends no unplaced keyframes any more
  stats_.unplaced_joined += static_cast<int64_t>(result.from_pinned);
  // keyframes: the frames a SLAM map is made of
  stats_.frames_inserted += static_cast<int64_t>(result.inserted.size());
  write_journal(msg, result);
  journal_released_pins(were_pinned);
  compact_journal_if_due();
  if (result.rebuilt) {
    ++stats_.rebuilds;
    stats_.last_rebuild_keyframes = static_cast<double>(result.rebuild_keyframes);
    revision_ = (revision_ / kRebuildRevisionStep + 1) * kRebuildRevisionStep - 1;
  }
  return maybe_publish(result.rebuilt);
}

}  // namespace kestrel::mapper
