#pragma once
// Frames and poses in, occupancy map out: the mapper as the process and the offline tool use
// it (no LCM, no files, no clock).
//
// Two ways to feed it:
//  * insert(frame, T_world_camera) with poses from any source (ground truth, the estimator,
//    a trajectory file): the frame goes into the map at once; every frame that moved more than
//    keyframe_translation_m / keyframe_rotation_deg since the last keyframe (the paper's rule,
//    25 cm / 10 degrees) is also stored as a keyframe.
//  * SLAM: buffer_frame(frame) for every frame, then apply_graph(keyframes) for every
//    SLAM_GRAPH revision. A keyframe seen for the first time is stored (its frame is found in
//    the buffer by utime) and inserted; if a stored keyframe moved by more than
//    rebuild_translation_m / rebuild_rotation_deg (a loop closure, a re-optimisation), the map
//    is rebuilt from all stored keyframes at their new poses, at most once per
//    rebuild_interval_s of sensor time (later moves wait for the next allowed rebuild).
//
// The log-odds of a frame cannot be taken out of a clamped map, so moved keyframes mean a
// rebuild rather than an update. A rebuild inserts the keyframes in the order they were stored; copies of the
// map taken along the way (checkpoints, every checkpoint_every keyframes, within a memory
// budget) each remember which keyframes at which poses they hold, so the next rebuild starts
// from the newest checkpoint whose keyframes are unchanged and re-inserts only the rest. When a
// loop closure moves only the later part of the trajectory, that is the later part only; the
// result is the same map as a rebuild from scratch (the same insertions in the same order).

#include <Eigen/Geometry>
#include <cstdint>
#include <deque>
#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "common/rgbd_frame.h"
#include "mapper/keyframe_store.h"
#include "mapper/options.h"
#include "mapper/scan.h"
#include "mapper/scan_integrator.h"
#include "mapper/voxel_map.h"

namespace kestrel::mapper {

struct MapperOptions {
  MapOptions map;
  ScanOptions scan;
  KeyframeOptions keyframes;
  double keyframe_translation_m = 0.25;  ///< insert(): store a keyframe after this much motion
  double keyframe_rotation_deg = 10.0;   ///< ... or this much rotation
  double rebuild_translation_m = 0.02;   ///< apply_graph(): a keyframe moved by more -> rebuild
  double rebuild_rotation_deg = 0.5;
  double rebuild_interval_s = 1.0;       ///< at most one rebuild per this much sensor time
  double frame_buffer_s = 5.0;           ///< frames kept for SLAM keyframes to refer to
  int max_pinned_frames = 300;           ///< frames kept past the buffer for keyframes SLAM has not placed yet (pin())
  /// Rebuild checkpoints: a copy of the map after every this many keyframes (in stored order),
  /// so a rebuild starts from the last one whose keyframes did not move (0 = none).
  int checkpoint_every = 8;
  double checkpoint_megabytes = 128.0;   ///< budget of the copies; over it every other one goes
  void validate() const;
};

/// One keyframe of a SLAM graph revision.
struct GraphKeyframe {
  int64_t id = 0;
  int64_t utime = 0;
  Eigen::Isometry3d T_world_camera = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_camera_depth = Eigen::Isometry3d::Identity();  ///< slam_keyframe_t's
};

struct GraphResult {
  std::vector<int64_t> inserted;  ///< ids of the new keyframes stored and put into the map
  std::vector<int64_t> moved;  ///< ids of the stored keyframes that moved beyond the threshold
  size_t missing = 0;    ///< new keyframes whose frame was not (or no longer) buffered
  size_t from_pinned = 0;  ///< new keyframes whose frame was pinned (Mapper::pin)
  bool rebuilt = false;  ///< the map was rebuilt from the stored keyframes
  size_t rebuild_keyframes = 0;
  size_t reinserted = 0;  ///< keyframes the rebuild inserted (the rest came from a checkpoint)
};

class Mapper {
 public:
  /// Throws std::invalid_argument naming the option for bad options.
  explicit Mapper(const MapperOptions& options = {});

  /// Inserts a frame seen from T_world_camera (of its depth image). Throws InputError (naming
  /// `what`) for a frame without depth, a broken frame or pose. Returns the scan's update.
  const ScanUpdate& insert(const RgbdFrame& frame, const Eigen::Isometry3d& T_world_camera,
                           const char* what = "frame");

  /// The full-size colour image of a frame buffered without it, made when wanted; throws
  /// InputError when it cannot be (a corrupt image).
  using ColourSource = std::function<cv::Mat()>;
  /// SLAM mode: keeps the frame (decimated) for keyframes that name its utime later. With
  /// `colour`, `frame` comes without its colour (rgb empty) and `colour` makes it the first
  /// time buffered() is asked for the frame (a keyframe, a pinned or a located frame takes
  /// it): most frames never are. A frame whose colour fails, for any reason, is kept without
  /// it (colour_lost()).
  void buffer_frame(const RgbdFrame& frame, const char* what = "frame", ColourSource colour = {});
  /// Buffered frames whose deferred colour could not be made (they went on without colour,
  /// which only the PLY export uses), and the last reason.
  size_t colour_lost() const { return colour_lost_; }
  const std::string& colour_lost_reason() const { return colour_lost_reason_; }
  /// SLAM mode: one graph revision.
  GraphResult apply_graph(const std::vector<GraphKeyframe>& keyframes);
  enum class Located { kInserted, kNotBuffered };
  /// SLAM mode: the buffered frame at `located.utime`, which SLAM located on its map without
  /// making it a keyframe (a localisation-only flight makes none): stored under `located.id`
  /// (next_located_id(): no graph names it, so no graph moves it) and inserted. Nothing changes
  /// for a frame no longer buffered.
  Located add_located(const GraphKeyframe& located);
  /// An id for a located frame: above every SLAM keyframe id (a utime in microseconds plus an
  /// index) and every id stored, so that ids still grow with time (the budget's tie-break).
  int64_t next_located_id() const;
  static constexpr int64_t kFirstLocatedId = int64_t{1} << 62;
  /// SLAM mode: the buffered (decimated) frame at `utime`, if it still is (in the buffer or
  /// pinned), with its colour.
  const RgbdFrame* buffered(int64_t utime) const;
  /// SLAM mode: keeps the buffered frame at `utime` past the buffer's time until a graph names
  /// it: a keyframe SLAM made before it placed the camera in its saved map, which joins the map
  /// only when the placement comes, maybe long after (SLAM_GRAPH_UNPLACED). At most
  /// max_pinned_frames are kept, the oldest let go first. kGone: the frame is no longer
  /// buffered (nothing to keep).
  enum class Pin { kPinned, kAlready, kGone };
  Pin pin(int64_t utime);
  /// Lets go of every pinned frame but those at `utimes` (SLAM's current unplaced keyframes;
  /// empty: all, once SLAM placed the camera and sends whole graphs).
  void keep_pinned(const std::set<int64_t>& utimes);
  size_t pinned() const { return pinned_.size(); }
  /// The pinned frames, oldest first (for the journal's compaction).
  std::vector<const RgbdFrame*> pinned_frames() const;
  /// A restarted mapper (map_node.h's journal): a frame pinned before the restart, as it was
  /// pinned (decimated), pinned again; InputError for a broken frame. Same result as pin().
  Pin restore_pinned(RgbdFrame decimated);

  /// A restarted mapper (map_node.h's journal): a keyframe stored before the restart, its frame
  /// as stored then. It goes into the store, not yet into the map: rebuild() after the last.
  void restore_keyframe(const GraphKeyframe& keyframe, RgbdFrame decimated);
  /// A restarted mapper: a graph that moved stored keyframes then; they move as apply_graph()
  /// moved them (the same thresholds), so the restored poses are the ones the store had.
  /// Returns how many moved.
  size_t restore_poses(const std::vector<GraphKeyframe>& keyframes);
  /// Rebuilds the map from the stored keyframes at their current poses; returns how many were
  /// inserted (the others came from a checkpoint).
  size_t rebuild();
  /// Rebuilds from nothing (ignores the checkpoints, keeps them; for comparisons).
  size_t rebuild_from_scratch();

  /// Forgets the map, the keyframes and the buffered frames.
  void reset();

  const VoxelMap& map() const { return map_; }
  const KeyframeStore& keyframes() const { return keyframes_; }
  const MapperOptions& options() const { return options_; }
  size_t frames_inserted() const { return frames_inserted_; }
  size_t rebuilds() const { return rebuilds_; }
  size_t checkpoints() const { return checkpoints_.size(); }
  size_t checkpoint_bytes() const;

 private:
  void integrate(const RgbdFrame& decimated, const Eigen::Isometry3d& T_world_camera, int64_t utime,
                 const char* what);
  using Placed = std::pair<int64_t, Eigen::Isometry3d>;  // keyframe id, pose it was inserted at
  struct Checkpoint {
    std::vector<Placed> keyframes;  // what the map holds, in insertion (time) order
    VoxelMap map;
  };
  void integrate_keyframe(const StoredKeyframe& kf);
  /// Stores a keyframe made from a buffered frame, inserting it into the map now unless a
  /// rebuild is about to insert everything.
  void store(StoredKeyframe kf, bool insert_now);
  // Moves the stored keyframes of `graph` that moved beyond the rebuild thresholds; the others
  // go to `fresh` when given. Returns the ids of those that moved.
  std::vector<int64_t> move_stored(const std::vector<GraphKeyframe>& graph,
                                   std::vector<GraphKeyframe>* fresh);
  void maybe_checkpoint();
  size_t rebuild_from(bool use_checkpoints);

  MapperOptions options_;
  ScanIntegrator integrator_;
  VoxelMap map_;
  KeyframeStore keyframes_;
  ScanUpdate update_;
  Scan scan_;                      // reused: a fresh one per frame cost page faults
  struct Buffered {
    RgbdFrame decimated;
    ColourSource colour;        // set until the colour is made (buffered())
    PinholeCamera full_camera;  // the camera of the colour `colour` makes
    std::string what;           // the frame's source, for errors
  };
  // By increasing utime. Mutable: buffered() makes a deferred colour on first use, which
  // changes what is cached, not what the frame is.
  mutable std::deque<Buffered> buffer_;
  mutable size_t colour_lost_ = 0;
  mutable std::string colour_lost_reason_;
  std::map<int64_t, RgbdFrame> pinned_;  // utime -> frame kept past the buffer (pin())
  Pin hold_pinned(RgbdFrame frame);      // into pinned_, the oldest let go past the limit
  bool have_last_keyframe_ = false;
  Eigen::Isometry3d last_keyframe_pose_ = Eigen::Isometry3d::Identity();
  int64_t next_keyframe_id_ = 0;
  int64_t last_rebuild_utime_ = -1;
  bool rebuild_pending_ = false;
  size_t frames_inserted_ = 0;
  size_t rebuilds_ = 0;
  // The live map is exactly sequence_'s keyframes inserted in order (false once insert() put
  // a non-keyframe frame in, or a stored keyframe was replaced).
  bool map_is_sequence_ = true;
  std::vector<Placed> sequence_;
  std::vector<Checkpoint> checkpoints_;  // increasing length, each a prefix of the next
};

}  // namespace kestrel::mapper
