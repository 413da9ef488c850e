// kestrel-mapper: the occupancy map process. Reads CAMERA_RGBD and SLAM_GRAPH (or, with
// --pose-source ground-truth, GROUND_TRUTH) and publishes MAP_OCTOMAP, rate-limited in sensor
// time, with heartbeats and lock-step replay (RESET forgets the map). With --journal it keeps its
// keyframes on disk and restores them when restarted. On exit it can write the final map
// (--save). The logic is MapNode (map_node.h); this file only wires it to LCM.

#include <spdlog/spdlog.h>

#include <memory>
#include <stdexcept>
#include <string>

#include "common/cli.h"
#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/node.h"
#include "mapper/cli_options.h"
#include "mapper/map_node.h"
#include "mapper/octree_io.h"

namespace {

using namespace kestrel;

struct Options {
  std::string name = "mapper";
  std::string lcm_url;
  std::string pose_source = "slam";
  std::string format = "binary";
  std::string save;
  mapper::NodeOptions node;
};

// Each older journal deleted so that at most --journal-keep of its kind stay is named in the
// log: nothing on disk goes without a trace.
void log_pruned_journals(const mapper::MapNode& map, int keep) {
  for (const std::string& removed : map.journal_pruned().removed)
    spdlog::info("deleted {}: the oldest beyond the {} journals of its kind kept (--journal-keep)", removed, keep);
  for (const std::string& failure : map.journal_pruned().failures)
    spdlog::warn("journals kept aside: {}", failure);
}

int serve(Options& o) {
  o.node.pose_source = o.pose_source == "slam" ? mapper::PoseSource::kSlamGraph : mapper::PoseSource::kGroundTruth;
  o.node.full_format = o.format == "full";
  mapper::check_node_options(o.node);
  if (!o.save.empty()) mapper::format_of(o.save);  // a bad extension is an error now, not at exit
  mapper::MapNode map(o.node);
  if (!o.node.journal_path.empty()) {
    if (!map.journal_error().empty()) {
      spdlog::error("{}: {}{}; the file is left as it was and the map goes on without a journal",
                    o.node.journal_path, map.journal_damage().empty() ? "" : "damaged (" + map.journal_damage() + "), ",
                    map.journal_error());
    } else if (!map.journal_damage().empty()) {
      spdlog::warn("{}: damaged ({}); the damaged file is kept as {}, journalling goes on in a fresh copy of "
                   "what was read", o.node.journal_path, map.journal_damage(), map.journal_kept_aside());
      log_pruned_journals(map, o.node.journal_keep);
    }
    spdlog::info("journal {}: {} keyframes restored, {} frames of unplaced keyframes pinned again", o.node.journal_path,
                 map.stats().keyframes_restored, map.stats().pinned_restored);
  }

  std::unique_ptr<transport::Node> node;
  node = std::make_unique<transport::Node>(o.name, o.lcm_url);  // UnavailableError: exit 4
  node->advertise(channel::kMapOctomap);
  // The map's health (DEGRADED once its journal is given up, from the start or later).
  const auto report_health = [&] {
    const mapper::MapNode::Health health = map.health();
    node->set_health(health.state, health.message);
  };
  node->on_reset([&] {
    const bool journalling = !o.node.journal_path.empty() && map.journal_error().empty();
    map.reset();
    if (!map.journal_kept_aside().empty())
      spdlog::info("reset: the journal starts again; what it held is kept as {}", map.journal_kept_aside());
    log_pruned_journals(map, o.node.journal_keep);
    if (journalling && !map.journal_error().empty()) {
      spdlog::error("journal stopped (the map goes on without it): {}", map.journal_error());
      report_health();
    }
  });
  auto publish = [&](const std::optional<octomap_t>& msg) {
    if (msg) node->publish(channel::kMapOctomap, *msg);
  };
  node->subscribe<rgbd_frame_t>(channel::kCameraRgbd, [&](const rgbd_frame_t& m) {
    publish(map.on_frame(m, channel::kCameraRgbd));
  });
  // A frame's colour is decoded when a keyframe, a pin or a located frame takes it; one that
  // fails leaves the frame its depth, and is said here.
  auto colour_checked = [&](auto&& handle) {
    const size_t lost = map.mapper().colour_lost();
    handle();
    if (const size_t now = map.mapper().colour_lost(); now > lost)
      spdlog::warn("{} frame(s) kept without their colour (the map has their depth): {}", now - lost,
                   map.mapper().colour_lost_reason());
  };
  // Graphs and corrections may journal: a journal given up on the way is said at once. (Here,
  // not in the block below: the handlers keep a reference to it for as long as the node spins.)
  auto journalled = [&](auto&& handle) {
    const bool journalling = !o.node.journal_path.empty() && map.journal_error().empty();
    const int compactions = map.journal_compactions();
    const std::string compaction_error = map.journal_compaction_error();
    colour_checked([&] { publish(handle()); });
    if (map.journal_compactions() > compactions)
      spdlog::info("journal {} compacted to the {} stored keyframes", o.node.journal_path,
                   map.mapper().keyframes().size());
    if (!map.journal_compaction_error().empty() && map.journal_compaction_error() != compaction_error)
      spdlog::warn("journal not compacted (it is kept as it was and appended to): {}", map.journal_compaction_error());
    if (journalling && !map.journal_error().empty()) {
      spdlog::error("journal stopped (the map goes on without it): {}", map.journal_error());
      report_health();
    }
  };
  if (o.node.pose_source == mapper::PoseSource::kSlamGraph) {
    // Graphs are rare and each may trigger a rebuild: never drop one.
    node->subscribe<slam_graph_t>(channel::kSlamGraph, [&](const slam_graph_t& m) {
      journalled([&] { return map.on_graph(m, channel::kSlamGraph); });
    }, 0);
    node->subscribe<slam_graph_t>(channel::kSlamGraphUnplaced, [&](const slam_graph_t& m) {
      colour_checked([&] { map.on_unplaced_graph(m, channel::kSlamGraphUnplaced); });
    }, 0);
    if (o.node.insert_located) {
      node->subscribe<slam_correction_t>(channel::kSlamCorrection, [&](const slam_correction_t& m) {
        journalled([&] { return map.on_correction(m, channel::kSlamCorrection); });
      }, 0);
    }
  } else {
    node->subscribe<ground_truth_t>(channel::kGroundTruth, [&](const ground_truth_t& m) {
      publish(map.on_ground_truth(m, channel::kGroundTruth));
    }, 0);
  }
  // A restored map goes out at once: the planner should not wait for the next keyframe.
  if (map.stats().keyframes_restored > 0) publish(map.map_message());
  // Not RUNNING regardless: a journal that could not be continued at start is reported too.
  report_health();
  spdlog::info("{}: CAMERA_RGBD + {} -> MAP_OCTOMAP at {} m", o.name,
               o.pose_source == "slam" ? "SLAM_GRAPH" : "GROUND_TRUTH", o.node.mapper.map.resolution_m);
  const int status = node->spin();
  const auto& s = map.stats();
  spdlog::info("{} frames ({} inserted, {} without pose), {} graphs, {} rebuilds, {} maps published ({} sent again), {} rejected",
               s.frames, s.frames_inserted, s.frames_without_pose, s.graphs, s.rebuilds, s.published, s.repeated,
               node->counters().messages_rejected);
  if (o.node.insert_located)
    spdlog::info("{} frames SLAM located inserted, {} no longer buffered", s.located, s.located_missing);
  if (s.unplaced_pinned > 0)
    spdlog::info("{} frames of keyframes SLAM made before placing the camera kept past the buffer, {} of them joined the map",
                 s.unplaced_pinned, s.unplaced_joined);
  // Where the memory is (the soak's question): the map, the keyframes kept for rebuilds and the
  // rebuild checkpoints, each within its budget (--keyframe-megabytes, checkpoints' 128 MB).
  const mapper::Mapper& m = map.mapper();
  spdlog::info("memory: map {:.1f} MB; {} stored keyframes {:.1f} MB ({} dropped); {} checkpoints {:.1f} MB",
               m.map().memory_bytes() / 1e6, m.keyframes().size(), m.keyframes().bytes() / 1e6,
               m.keyframes().dropped(), m.checkpoints(), m.checkpoint_bytes() / 1e6);
  if (!o.save.empty()) {
    mapper::write_map_file(map.mapper().map(), o.save);
    spdlog::info("wrote {}", o.save);
  }
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  cli::App app("mapper",
               "Occupancy voxel map (OctoMap): CAMERA_RGBD + SLAM_GRAPH (or GROUND_TRUTH) -> MAP_OCTOMAP");
  Options o;
  app.add_option("--name", o.name, "Process name in heartbeats")->capture_default_str();
  app.add_option("--lcm-url", o.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  app.add_option("--pose-source", o.pose_source,
                 "slam: keyframes and poses from SLAM_GRAPH (rebuilt on loop closure); ground-truth: "
                 "every frame at its GROUND_TRUTH pose")
      ->check(CLI::IsMember({"slam", "ground-truth"}))
      ->capture_default_str();
  app.add_option("--publish-period", o.node.publish_period_s, "MAP_OCTOMAP at most this often, s of sensor time")
      ->check(CLI::Range(0.0, 1e6))
      ->capture_default_str();
  app.add_option("--format", o.format, "MAP_OCTOMAP stream: binary (.bt, free/occupied) or full (.ot, log-odds)")
      ->check(CLI::IsMember({"binary", "full"}))
      ->capture_default_str();
  app.add_option("--max-pose-gap", o.node.max_pose_gap_s, "ground-truth: largest gap to interpolate across, s")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_option("--save", o.save, "Write the final map here on exit (.bt or .ot)");
  app.add_option("--journal", o.node.journal_path,
                 "slam: journal the keyframes to this file and, if it exists, restore the map from it "
                 "first (a mapper restarted in flight; kestrel launch gives each launch its own)");
  app.add_flag("--journal-is-map", o.node.journal_is_map,
               "The journal is a building's saved map (kestrel launch --map): a lock-step RESET before any input "
               "keeps the map restored from it (by default a RESET forgets it: a replay of its own flight)");
  app.add_flag("--insert-located", o.node.insert_located,
               "slam: also insert the frames SLAM located on its map without a keyframe (SLAM_CORRECTION), at the "
               "corrected pose, kept and journaled as keyframes no graph moves: a localisation-only flight updates "
               "the map")
      ->capture_default_str();
  app.add_option("--journal-keep", o.node.journal_keep,
                 "Journals set aside kept of each kind (FILE.reset-*, FILE.damaged-*): the newest; each older one "
                 "is deleted, and logged, when another is set aside")
      ->check(CLI::Range(1, 1000000))
      ->capture_default_str();
  app.add_option("--journal-compact-mb", o.node.journal_compact_mb,
                 "The journal is compacted (replaced at once by the stored keyframes' records) when it is larger "
                 "than twice the stored keyframes plus this many MB")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  mapper::add_mapper_options(app, o.node.mapper);
  return app.run(argc, argv, [&] { return serve(o); });
}
