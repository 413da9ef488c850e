#pragma once
// The mapper process's logic on decoded messages, without LCM itself: main.cpp only subscribes
// and publishes, and the tests drive this class with messages directly.
//
// Pose sources:
//  * kSlamGraph (default): CAMERA_RGBD frames are buffered; every SLAM_GRAPH revision inserts
//    its new keyframes and rebuilds the map when keyframes moved (Mapper::apply_graph).
//  * kGroundTruth: each frame is inserted at the GROUND_TRUTH pose interpolated at its depth
//    time, once poses on both sides of that time have arrived (for bench runs before SLAM
//    exists, and to compare maps). A frame in a gap of the ground truth is dropped and counted.
//
// Journal (kSlamGraph, NodeOptions::journal_path): every keyframe stored and every graph that
// moved stored keyframes is appended to a file (keyframe_journal.h). A node started on an
// existing journal first restores those keyframes at the poses they had and rebuilds the map
// from them, so a mapper killed and restarted in flight carries on with its map; keyframes
// SLAM made while it was down are missing (their frames went by). A damaged journal is read
// past the damage, kept aside whole and continued as a fresh copy; RESET starts the journal
// again empty and keeps the old one aside (keyframe_journal.h): no journal is ever cut. Of the
// journals set aside, NodeOptions::journal_keep of each kind are kept; the older ones deleted
// are in journal_pruned(), for the process to log. A journal that has grown past twice the
// store (keyframes the store dropped, poses since moved) is compacted: replaced at once by the
// same store's records (NodeOptions::journal_compact_mb; journal_compactions()).
// A journal that cannot be written mid-flight (a full disk), or cannot be continued at start
// (its folder cannot be written), is given up, not the map: journal_error() says why, health()
// is DEGRADED with it, and mapping goes on.
//
// Located frames (NodeOptions::insert_located, kSlamGraph): the frame of every SLAM_CORRECTION
// that is not its keyframe's own (a frame SLAM located on its map without making it a keyframe,
// or the one frame sent to a restarted estimator) goes into the map at the corrected pose, and
// into the store and the journal as a keyframe of its own (Mapper::next_located_id) that no
// graph moves: a localisation-only flight makes no keyframes, yet what changed in the building
// (a door closed) reaches the map. Its pose is its colour time's (no depth-time correction).
//
// MAP_OCTOMAP is produced at most once per publish_period_s of sensor time, and at once after
// a rebuild. In kSlamGraph mode the map changes only with SLAM's keyframes, and a hovering
// vehicle makes none: the last map then goes out again (same revision) each publish_period_s
// of frames, so a process started since (a restarted planner) is not left without one.
// Everything is driven by the messages' utime, so a lock-step replay publishes the same maps
// at the same points every time. Bad messages throw InputError naming the channel
// (the Node counts and drops them); a frame older than the previous one is one of those.

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>

#include "common/trajectory.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/octomap_t.hpp"
#include "kestrel/process_status_t.hpp"
#include "kestrel/rgbd_frame_t.hpp"
#include "kestrel/slam_correction_t.hpp"
#include "kestrel/slam_graph_t.hpp"
#include "mapper/keyframe_journal.h"
#include "mapper/mapper.h"

namespace kestrel::mapper {

enum class PoseSource { kSlamGraph, kGroundTruth };

struct NodeOptions {
  MapperOptions mapper;
  PoseSource pose_source = PoseSource::kSlamGraph;
  double publish_period_s = 1.0;    ///< MAP_OCTOMAP at most this often (sensor time)
  bool full_format = false;         ///< FORMAT_FULL (.ot, log-odds) instead of FORMAT_BINARY (.bt)
  double max_pose_gap_s = 0.1;      ///< kGroundTruth: largest gap to interpolate across
  int max_pending_frames = 90;      ///< kGroundTruth: frames waiting for a pose after theirs
  std::string journal_path;         ///< kSlamGraph: journal here, restore from it ("" = none)
  /// The journal is a building's saved map (kestrel launch --map): a RESET before any input
  /// since the start (a lock-step session's first) leaves the map it restored, where the new
  /// flight begins. Without it a RESET forgets that map (a replay of the flight that wrote the
  /// journal feeds the same keyframes again).
  bool journal_is_map = false;
  /// Journals set aside kept of each kind (reset, damaged), the newest; >= 1.
  int journal_keep = kDefaultKeptJournals;
  /// The journal is compacted (JournalWriter::compact) once it is larger than twice the
  /// stored keyframes' bytes plus this many MB, so it stays within about twice the store
  /// while each compaction writes at most what the journal grew by since the last; > 0.
  double journal_compact_mb = 64.0;
  /// kSlamGraph: also insert the frames SLAM located on its map (above).
  bool insert_located = false;
  void validate() const;
};

struct NodeStats {
  int64_t frames = 0;             ///< frames accepted
  int64_t frames_inserted = 0;    ///< frames put into the map (slam: new keyframes)
  int64_t frames_without_pose = 0;
  int64_t graphs = 0;
  int64_t rebuilds = 0;
  int64_t published = 0;          ///< maps made (repeats not counted)
  int64_t repeated = 0;           ///< the last map sent again (kSlamGraph, no new map for a period)
  double last_rebuild_keyframes = 0;
  int64_t keyframes_restored = 0;  ///< from the journal at start
  int64_t pinned_restored = 0;     ///< frames of unplaced keyframes pinned again from the journal at start
  int64_t located = 0;             ///< located frames inserted (insert_located)
  int64_t located_missing = 0;     ///< located frames no longer buffered
  int64_t unplaced_pinned = 0;     ///< frames of unplaced keyframes pinned (kept past the buffer)
  int64_t unplaced_joined = 0;     ///< of them, inserted when a graph joined their keyframes
};

class MapNode {
 public:
  /// With a journal_path, restores what the journal holds (InputError naming the file if it is
  /// not a journal; damage is reported by journal_damage(), the damaged file kept as
  /// journal_kept_aside()).
  explicit MapNode(const NodeOptions& options);

  /// Each returns the MAP_OCTOMAP message to publish now, if one is due.
  std::optional<kestrel::octomap_t> on_frame(const kestrel::rgbd_frame_t& msg, const char* channel);
  std::optional<kestrel::octomap_t> on_graph(const kestrel::slam_graph_t& msg, const char* channel);
  std::optional<kestrel::octomap_t> on_ground_truth(const kestrel::ground_truth_t& msg,
                                                    const char* channel);
  /// kSlamGraph: SLAM_GRAPH_UNPLACED, the keyframes SLAM made before it placed the camera in
  /// its saved map (in a frame of their own, not in the map): their frames are kept past the
  /// buffer (Mapper::pin; journaled, so a restarted mapper keeps them too) until the placement
  /// joins them and a SLAM_GRAPH names them; frames
  /// pinned for keyframes a later list leaves out, and all once a SLAM_GRAPH comes (SLAM sends
  /// whole graphs only once placed), are let go. Nothing goes into the map. Throws InputError
  /// naming the channel for a count that disagrees.
  void on_unplaced_graph(const kestrel::slam_graph_t& msg, const char* channel);
  /// insert_located: the frame the correction is for, if SLAM located it without a keyframe.
  std::optional<kestrel::octomap_t> on_correction(const kestrel::slam_correction_t& msg, const char* channel);
  /// The map as a message now, regardless of the rate limit (e.g. at shutdown).
  kestrel::octomap_t map_message();
  /// Forgets everything (lock-step replay RESET); the journal starts again, the old one kept
  /// as journal_kept_aside() if it held anything.
  void reset();

  const Mapper& mapper() const { return mapper_; }
  const NodeStats& stats() const { return stats_; }
  /// Why the journal was read only in part at start ("" = it was read whole, or there is none).
  const std::string& journal_damage() const { return journal_damage_; }
  /// Where the last journal set aside is kept: the damaged one at start, or the one the last
  /// reset() ended ("" = none was).
  const std::string& journal_kept_aside() const { return journal_kept_aside_; }
  /// Why journalling stopped ("" = it did not).
  const std::string& journal_error() const { return journal_error_; }
  /// How many times the journal was compacted since the start.
  int journal_compactions() const { return journal_ ? journal_->compactions() : 0; }
  /// Why the last compaction failed ("" = it did not): the journal is then kept as it was and
  /// appended to, and compaction is tried again once it has grown by journal_compact_mb.
  const std::string& journal_compaction_error() const { return journal_compaction_error_; }
  /// The older journals deleted (or that could not be) when the last one was set aside, so
  /// that at most journal_keep of its kind stay.
  const PrunedJournals& journal_pruned() const { return journal_pruned_; }

  struct Health {
    int8_t state = kestrel::process_status_t::STATE_RUNNING;
    std::string message;
  };
  /// What the process reports: RUNNING, or DEGRADED "journal stopped: <why>" once the journal
  /// was given up (the map goes on, but a restart would no longer get it back).
  Health health() const;

 private:
  std::optional<kestrel::octomap_t> maybe_publish(bool now);
  std::optional<kestrel::octomap_t> repeat_map(int64_t frame_utime);
  void insert_pending();
  /// Runs `write` on the journal, if there is one; a failure gives the journal up (journal_error()).
  void journal(const std::function<void(JournalWriter&)>& write);
  void write_journal(const kestrel::slam_graph_t& msg, const GraphResult& result);
  void compact_journal_if_due();
  /// The utimes of the frames pinned now.
  std::set<int64_t> pinned_utimes() const;
  /// Journals the frames of `were_pinned` that are no longer pinned (joined or let go), so a
  /// restart does not pin them again.
  void journal_released_pins(const std::set<int64_t>& were_pinned);

  NodeOptions options_;
  Mapper mapper_;
  NodeStats stats_;
  int64_t last_frame_utime_ = 0;
  int64_t last_published_utime_ = -1;
  int64_t revision_ = 0;
  int64_t last_graph_revision_ = -1;
  std::optional<kestrel::octomap_t> last_map_;  // as last sent
  int64_t last_map_frame_utime_ = 0;            // the newest frame when it was last sent
  std::deque<RgbdFrame> pending_;  // kGroundTruth: frames waiting for their pose
  Trajectory poses_;               // kGroundTruth: T_world_camera, recent
  std::unique_ptr<JournalWriter> journal_;
  std::string journal_damage_;
  std::string journal_kept_aside_;
  std::string journal_error_;
  std::string journal_compaction_error_;
  double compact_retry_bytes_ = 0.0;  // no compaction below this journal size (after a failure)
  bool input_since_start_ = false;  ///< a frame, graph or pose handled since the start or reset()
  PrunedJournals journal_pruned_;
};

}  // namespace kestrel::mapper
