// kestrel-slam: keyframes, loop closure and pose-graph optimisation (PAPER.md section 3).
// As a process (default) it reads CAMERA_RGBD and VO_UPDATE and publishes SLAM_GRAPH after every
// new keyframe and SLAM_CORRECTION after every optimisation (on a saved map, before the camera is
// placed, SLAM_GRAPH_UNPLACED instead: the keyframes waiting to join), with heartbeats and
// lock-step replay. With --tum DIR it runs VO and SLAM in process over a TUM RGB-D folder and writes the
// optimised trajectory (TUM format). See slam/README.md.

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <ctime>
#include <iostream>
#include <memory>
#include <set>
#include <string>

#include "common/cli.h"
#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/node.h"
#include "kestrel/map_save_request_t.hpp"
#include "slam/memory_policy.h"
#include "slam/map/map_file.h"
#include "slam/place/builtin_vocabulary.h"
#include "slam/slam_adapter.h"
#include "sensors/profile_file.h"
#if KESTREL_SLAM_OFFLINE
#include "common/numbers.h"
#include "drivers/tum/tum_sequence.h"
#include "slam/sequence_run.h"
#include "vo/options.h"
#include "vo/sequence_run.h"
#endif

namespace {

using namespace kestrel;
using namespace kestrel::slam;

struct Options {
  std::string vocabulary = "builtin";
  std::string kernel = "dcs";
  std::string sensor;  // a sensor profile's name or file; empty: the TUM folder's, else each frame's
  std::string map, save_map;  // folders of saved maps (slam/map/map_file.h)
  // Offline.
  std::string tum, out, vo_out;
  // Process.
  std::string name = "slam";
  std::string lcm_url;
  AdapterOptions adapter;
  std::string graph_channel = channel::kSlamGraph;
  std::string correction_channel = channel::kSlamCorrection;
};

// Why frames over covered ground became keyframes or were carried (Slam::CoverageMisses), as
// both the offline run and the process say it at the end.
std::string coverage_summary(const Slam::CoverageMisses& m) {
  return fmt::format(
      "keyframes instead: {} with none near, {} none verified, {} located too far; carried instead: {} too "
      "featureless to locate, {} none verified but well predicted, {} none verified with too few points for a keyframe; "
      "{} located too far closed their loop without a keyframe",
      m.none_near, m.not_verified, m.too_far, m.featureless, m.unverified_carried, m.few_points_carried,
      m.closed_in_place);
}

void add_options(cli::App& app, Options& o, SlamOptions& s) {
  app.add_option("--vocabulary", o.vocabulary,
                 "Place-recognition vocabulary: builtin (trained on the simulator's worlds, see slam/README.md), "
                 "online (built from the keyframes as they come) or a file (kestrel-slam-vocabulary's output)")
      ->capture_default_str();
  app.add_option("--keyframe-distance", s.keyframes.min_translation_m, "New keyframe after this motion, m")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--keyframe-angle", s.keyframes.min_rotation_rad, "New keyframe after this rotation, rad")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_flag("--reuse-keyframes,!--no-reuse-keyframes", s.coverage.reuse_keyframes,
               "Where a keyframe already covers the view, locate the frame in it instead of making a new "
               "keyframe (memory grows with the ground covered, not the time flown)")
      ->capture_default_str();
  app.add_option("--reuse-max-correction", s.coverage.max_correction_m,
                 "A frame is located in a covering keyframe only within this of its estimate, m (more: a loop closure)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_flag("--reuse-close-loops,!--no-reuse-close-loops", s.coverage.close_loops_in_place,
               "A covered frame located beyond --reuse-max-correction closes the loop by an edge between the covering "
               "keyframe and its reference's, when it verifies as a loop and agrees with the odometry, instead of "
               "through a new keyframe (a revisit adds no keyframe)")
      ->capture_default_str();
  app.add_option("--reuse-carry-sigmas", s.coverage.carry_within_sigmas,
                 "A covered frame no keyframe verifies is carried at its predicted pose, not made a keyframe, while "
                 "this many of the prediction's sigmas lie within the correction bounds (--reuse-max-correction and its "
                 "angle) and its reference's keyframe is a graph neighbour of a covering one; 0: never (localising only: "
                 "always carried)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--reuse-min-points", s.coverage.min_points_to_verify,
                 "A covered frame none verifies, too uncertain to carry by --reuse-carry-sigmas, is carried all the same, "
                 "not made a keyframe, when it has fewer feature points with depth than this: a keyframe of it would "
                 "hardly ever verify (0: never)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--keyframe-megabytes", s.memory.max_megabytes,
                 "Memory budget of the keyframes' features, MB: over it, keyframes of places seen from many similar "
                 "views are thinned (kept in the graph, no longer matched)")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--loop-min-age", s.loops.min_age_s, "Loop candidates are at least this much older, s")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--loop-max-distance", s.loops.max_distance_m,
                 "Loop candidates lie this close to the current estimate, m (0: no gate)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--loop-max-angle", s.loops.max_angle_rad, "... and turned at most this much, rad")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--candidates", s.loops.max_candidates, "Loop candidates verified at most, best first")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--loop-odometry-sigmas", s.loop_consistency.sigmas,
                 "A verified loop must agree with the odometry between its keyframes within this many sigmas (0: no check)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--min-inliers", s.verification.min_inliers, "Inliers a loop closure needs")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_flag("--odometry-covariance,!--no-odometry-covariance", s.odometry.use_reported,
               "Odometry edges take the VO's reported covariance (else the constant noise model)")
      ->capture_default_str();
  app.add_option("--kernel", o.kernel, "Robust kernel on loop closures: none, huber, cauchy or dcs")
      ->check(CLI::IsMember({"none", "huber", "cauchy", "dcs"}))->capture_default_str();
  app.add_option("--sensor", o.sensor,
                 "Camera profile, as kestrel-vo's (its timing corrects the keyframes' features, its noise "
                 "floors the loops'): a built-in one (simulator: global shutter; kinect1: rolling shutter, "
                 "depth before colour, loops 1 degree uncertain; default: nothing changed) or a profile file "
                 "of your own (sensors/README.md); by default the one each frame's sensor model names, or "
                 "default (with --tum the folder's: kinect1 for freiburg1)")
      ->check(CLI::Validator([](std::string& name) { return sensors::check_sensor_profile_name(name); }, "PROFILE"));
  app.add_option("--map", o.map,
                 "Start from the SLAM map saved in this folder: frames are relocalised in it (no pose prior), then "
                 "mapping goes on in its world (a new session); its vocabulary replaces --vocabulary");
  app.add_option("--save-map", o.save_map,
                 "Save the SLAM map (keyframes, features, graph, vocabulary) in this folder at the end (offline) or on "
                 "exit (process), for a later --map");
  app.add_flag("--localize-only", s.localize_only,
               "With --map: add no keyframe over the map (frames are located in it, relocalised again when lost); "
               "keyframes only where the vehicle leaves it")
      ->capture_default_str();
  app.add_option("--relocalisation-confirmations", s.relocalisation.confirmations,
                 "With --map: verified placements from different frames that must agree before the camera is placed")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--relocalisation-ratio", s.relocalisation.match_ratio,
                 "With --map: the ratio test of a placement's feature matching (best / second-best distance)")
      ->check(CLI::Range(0.0, 1.0))->capture_default_str();
  app.add_option("--map-unplaced-after", s.relocalisation.map_unplaced_after_s,
                 "With --map: seconds without a placement after which keyframes are made in a frame of their own, "
                 "joined to the map when the camera is placed (1e9: none before the placement)")
      ->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--tum", o.tum, "Offline: run VO + SLAM over this TUM RGB-D folder");
  app.add_option("--out", o.out, "Offline: write the optimised camera trajectory here (TUM format)");
  app.add_option("--vo-out", o.vo_out, "Offline: write the odometry-only trajectory here too");
  app.add_option("--name", o.name, "Process name in heartbeats")->capture_default_str();
  app.add_option("--lcm-url", o.lcm_url, "LCM URL (default: $LCM_DEFAULT_URL or kestrel's)");
  app.add_option("--camera-channel", o.adapter.camera_channel, "Channel of rgbd_frame_t")->capture_default_str();
  app.add_option("--vo-channel", o.adapter.vo_channel, "Channel of vo_update_t")->capture_default_str();
  app.add_option("--state-channel", o.adapter.state_channel,
                 "Channel of the estimator's state_t: its world frame becomes the map's (SLAM_GRAPH, SLAM_CORRECTION)")
      ->capture_default_str();
  app.add_option("--graph-channel", o.graph_channel, "Channel of slam_graph_t")->capture_default_str();
  app.add_option("--correction-channel", o.correction_channel, "Channel of slam_correction_t")
      ->capture_default_str();
}

std::string utc_now() {
  const std::time_t now = std::chrono::system_clock::to_time_t(std::chrono::system_clock::now());
  std::tm tm{};
  gmtime_r(&now, &tm);
  char text[32];
  std::strftime(text, sizeof(text), "%Y-%m-%dT%H:%M:%SZ", &tm);
  return text;
}

std::shared_ptr<const SlamMap> load_map(const std::string& dir) {
  if (dir.empty()) return nullptr;
  const auto t0 = std::chrono::steady_clock::now();
  auto map = std::make_shared<const SlamMap>(read_map(dir));  // InputError: exit 3
  spdlog::info("map {}: {} keyframes from {} session(s), read in {:.0f} ms", map_file_in(dir), map->keyframes.size(),
               map->sessions, std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  return map;
}

// Writes the map; false, writing nothing, when it has no keyframe: a map of nothing would be
// taken by the next flight for a building's map.
bool save_map(const std::string& dir, const SlamMap& map, const std::string& made_by) {
  if (map.keyframes.empty()) {
    spdlog::warn("map not saved in {}: no keyframe yet", dir);
    return false;
  }
  write_map(dir, map, MapProvenance{made_by, utc_now()});
  spdlog::info("map saved: {} ({} keyframes, {} session(s))", map_file_in(dir), map.keyframes.size(), map.sessions);
  return true;
}

void report_relocalisation(const std::optional<Relocalisation>& r, bool from_map) {
  if (!from_map) return;
  if (!r) {
    spdlog::warn("never placed in the map: no frame verified consistently against it");
    return;
  }
  const Eigen::Vector3d p = r->T_world_camera.translation();
  spdlog::info("relocalised at frame {} of those tried (utime {}) in keyframe {}: camera at ({:.3f}, {:.3f}, {:.3f}) m; "
               "{} keyframe(s) made before it joined the map",
               r->frames_tried, r->utime, r->keyframe_id, p.x(), p.y(), p.z(), r->keyframes_joined);
}

int run_offline(const Options& o, const SlamOptions& options, std::shared_ptr<const Vocabulary> vocabulary) {
  if (o.out.empty()) throw CLI::RequiredError("--out (with --tum)");
#if !KESTREL_SLAM_OFFLINE
  (void)vocabulary;
  throw CLI::ValidationError("--tum", "this build has no visual odometry (vo/ was absent)");
#else
  // Frames are decoded one at a time: a long sequence (e.g. a sim flight) need not fit in memory.
  const tum::TumSequence sequence(o.tum);
  // The camera's profile: as told, else the folder's (as kestrel-vo --tum).
  const sensors::SensorProfile sensor = o.sensor.empty() ? vo::tum_sensor(o.tum) : sensors::load_sensor_profile(o.sensor);
  std::cout << "camera profile: " << sensor.name << "\n";
  const std::shared_ptr<const SlamMap> map = load_map(o.map);
  const SlamRun run = run_slam_sequence(
      sequence.size(), [&sequence](size_t i) { return sequence.frame(i); }, sensor, vo::VoOptions{}, options,
      std::move(vocabulary), map);
  // Nothing is written for a run that estimated nothing, as by kestrel-vo --tum: a trajectory
  // of the first frame's identity pose alone, or of no pose, would read as a result.
  vo::require_usable(run.odometry, o.tum);  // InputError: exit 3
  report_relocalisation(run.relocalisation, map != nullptr);
  if (map && !run.relocalisation) {
    std::cerr << "slam: no frame of " << o.tum << " was placed in the map " << o.map << ": nothing written\n";
    return kExitFailure;
  }
  write_tum_trajectory(o.out, run.slam);
  if (!o.save_map.empty()) save_map(o.save_map, run.map, "kestrel-slam --tum " + o.tum);
  if (!o.vo_out.empty()) write_tum_trajectory(o.vo_out, run.vo);
  std::vector<double> ms = run.keyframe_ms;
  std::sort(ms.begin(), ms.end());
  std::cout << "frames: " << sequence.size() << ", with a pose: " << run.slam.size() << "\n"
            << "keyframes: " << run.keyframes << ", loop closures: " << run.loop_closures
            << " (" << run.candidates_verified << " candidates verified, " << run.inconsistent_loops
            << " verified but refused by the odometry check), re-anchored on a covering keyframe: "
            << run.reanchors << " (" << coverage_summary(run.coverage_misses) << ")\n";
  if (!ms.empty()) {
    std::cout << "ms per keyframe: median " << ms[ms.size() / 2] << ", p95 " << ms[ms.size() * 95 / 100]
              << ", max " << ms.back() << "\n";
  }
  // Each loop closure against the ground truth, when the folder has one.
  if (sequence.has_ground_truth()) {
    for (const LoopError& e : loop_errors(run, sequence.ground_truth())) {
      std::cout << "loop " << e.edge.from_utime << " -> " << e.edge.to_utime << ": ";
      if (e.has_truth) {
        std::cout << "error " << e.translation_m << " m, " << e.rotation_rad * 180.0 / kPi << " deg\n";
      } else {
        std::cout << "no ground truth\n";
      }
    }
  }
  return kExitOk;
#endif
}

int serve(const Options& o, const SlamOptions& options, std::shared_ptr<const Vocabulary> vocabulary) {
  if (!o.out.empty() || !o.vo_out.empty()) throw CLI::ValidationError("--out/--vo-out", "only with --tum");
  AdapterOptions adapter_options = o.adapter;
  if (!o.sensor.empty()) adapter_options.sensor = sensors::load_sensor_profile(o.sensor);
  const std::shared_ptr<const SlamMap> map = load_map(o.map);
  spdlog::info("camera profile: {}", o.sensor.empty() ? "each frame's sensor model" : o.sensor);
  SlamAdapter adapter = map ? SlamAdapter(map, options, adapter_options)
                            : SlamAdapter(options, std::move(vocabulary), adapter_options);
  std::unique_ptr<transport::Node> node;
  node = std::make_unique<transport::Node>(o.name, o.lcm_url);  // UnavailableError: exit 4
  node->advertise(o.graph_channel);
  node->advertise(o.correction_channel);
  // The unplaced keyframes go out beside the graph: SLAM_GRAPH_UNPLACED by default.
  const std::string unplaced_channel = o.graph_channel + "_UNPLACED";
  node->advertise(unplaced_channel);
  node->on_reset([&] { adapter.reset(); });
  auto publish = [&](const AdapterOutputs& out) {
    if (out.anchored) spdlog::info("map anchored in the estimator's world at keyframe {}",
                                 published_id(adapter.slam(), adapter.slam().keyframes().back().id));
    if (out.levelled_rad > 0.0)
      spdlog::info("map turned level by {:.2f} deg about keyframe {}: the estimator's gravity says it was tilted",
                   out.levelled_rad * 180.0 / kPi, published_id(adapter.slam(), adapter.slam().keyframes().back().id));
    if (out.graph) node->publish(o.graph_channel, *out.graph);
    if (out.unplaced) node->publish(unplaced_channel, *out.unplaced);
    if (out.correction) node->publish(o.correction_channel, *out.correction);
    if (out.step && out.step->relocalised) report_relocalisation(adapter.slam().relocalisation(), true);
    if (out.step && out.step->loop_closed && out.step->keyframe) {  // (a join is said with the relocalisation)
      spdlog::info("keyframe {} closes a loop with keyframe {} ({} inliers, {:.2f} px); chi2 {:.4g} -> {:.4g}",
                   published_id(adapter.slam(), out.step->keyframe_id),
                   published_id(adapter.slam(), out.step->loop_keyframe_id), out.step->loop.inliers,
                   out.step->loop.rms_px, out.step->optimisation->start_chi2, out.step->optimisation->final_chi2);
    } else if (out.step && out.step->loop_closed && !out.step->keyframe && !out.step->relocalised) {
      // Closed without a keyframe: the loop is the graph's newest edge (Slam::close_loop_in_place).
      const auto& loop = adapter.slam().graph().edges.back();
      spdlog::info("a frame located in keyframe {} closes a loop from it to keyframe {} without a keyframe ({} "
                   "inliers, {:.2f} px); chi2 {:.4g} -> {:.4g}; the frame {}",
                   published_id(adapter.slam(), adapter.slam().graph().ids[static_cast<size_t>(loop.from)]),
                   published_id(adapter.slam(), adapter.slam().graph().ids[static_cast<size_t>(loop.to)]),
                   out.step->loop.inliers, out.step->loop.rms_px, out.step->optimisation->start_chi2,
                   out.step->optimisation->final_chi2,
                   out.step->reanchored ? "located there" : "carried at its prediction (the graph disagrees)");
    }
  };
  node->subscribe<rgbd_frame_t>(o.adapter.camera_channel, [&](const rgbd_frame_t& m) { publish(adapter.on_frame(m)); });
  node->subscribe<vo_update_t>(o.adapter.vo_channel, [&](const vo_update_t& m) { publish(adapter.on_vo_update(m)); });
  node->subscribe<state_t>(o.adapter.state_channel, [&](const state_t& m) {
    const int restarts = adapter.estimator_restarts();
    publish(adapter.on_state(m));
    if (adapter.estimator_restarts() > restarts)
      spdlog::warn("{}: a new estimator (its seq started again): the next keyframe's {} gives it the map's world",
                   o.adapter.state_channel, o.correction_channel);
  });
  std::set<int64_t> answered;  // save requests answered (save-map asks again until answered)
  if (!o.save_map.empty()) {
    // Saving on request: the answer is the heartbeat's message, which `kestrel save-map` waits
    // for. A failed save (a full disk) leaves the process running and says why.
    node->subscribe<map_save_request_t>(channel::kSlamSaveMap, [&](const map_save_request_t& m) {
      if (!answered.insert(m.request_id).second) return;
      try {
        const SlamMap now = adapter.slam().map();
        if (!save_map(o.save_map, now, "kestrel-slam (process " + o.name + ", on request)")) {
          node->set_health(process_status_t::STATE_RUNNING,
                           fmt::format("map not saved for request {}: no keyframe yet", m.request_id));
          return;
        }
        node->set_health(process_status_t::STATE_RUNNING,
                         fmt::format("map saved for request {}: {} keyframes in {}", m.request_id,
                                     now.keyframes.size(), map_file_in(o.save_map)));
      } catch (const InputError& e) {
        spdlog::error("map not saved: {}", e.what());
        node->set_health(process_status_t::STATE_DEGRADED,
                         fmt::format("map not saved for request {}: {}", m.request_id, e.what()));
      }
    });
  }
  node->set_health(process_status_t::STATE_RUNNING, "");
  spdlog::info("{}: {} + {} -> {}, {}", o.name, o.adapter.camera_channel, o.adapter.vo_channel,
               o.graph_channel, o.correction_channel);
  const int status = node->spin();
  if (map && !adapter.slam().relocalisation()) report_relocalisation(std::nullopt, true);  // placed: said when it was
  if (!o.save_map.empty())
    save_map(o.save_map, adapter.slam().map(), "kestrel-slam (process " + o.name + ")");
  spdlog::info("{} keyframes ({} thinned, features {:.1f} MB), {} loop closures, {} frames re-anchored on a "
               "covering keyframe ({}), {} VO restarts "
               "bridged by the estimator, {} estimator restarts, {} levellings ({} tilts refused as too large), {} messages rejected",
               adapter.slam().keyframes().size(), adapter.slam().num_thinned(), adapter.slam().feature_bytes() / 1e6,
               adapter.slam().num_loop_closures(), adapter.slam().num_reanchors(),
               coverage_summary(adapter.slam().coverage_misses()), adapter.bridges(),
               adapter.estimator_restarts(), adapter.levellings(), adapter.levels_refused(),
               node->counters().messages_rejected);
  return status;
}

}  // namespace

int main(int argc, char** argv) {
  kestrel::slam::keep_freed_memory();
  cli::App app("slam",
               "SLAM: keyframes, loop closure and pose-graph optimisation. CAMERA_RGBD + VO_UPDATE -> "
               "SLAM_GRAPH + SLAM_CORRECTION, or with --tum an offline VO + SLAM run over a TUM folder.");
  Options o;
  SlamOptions options;
  add_options(app, o, options);
  return app.run(argc, argv, [&] {
    options.optimizer.kernel.type = parse_kernel_type(o.kernel);
    std::shared_ptr<const Vocabulary> vocabulary;
    if (o.vocabulary == "builtin") {
      vocabulary = builtin_vocabulary();
    } else if (o.vocabulary != "online") {
      vocabulary = std::make_shared<const Vocabulary>(Vocabulary::load(o.vocabulary));
    }
    return o.tum.empty() ? serve(o, options, vocabulary) : run_offline(o, options, vocabulary);
  });
}
