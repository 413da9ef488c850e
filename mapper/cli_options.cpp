#include "mapper/cli_options.h"

#include <stdexcept>

namespace kestrel::mapper {

void add_mapper_options(CLI::App& app, MapperOptions& o) {
  auto opt = [&](const char* name, double& v, const char* what) {
    app.add_option(name, v, what)->capture_default_str()->group("Map");
  };
  opt("--resolution", o.map.resolution_m, "Cell size, m");
  opt("--prob-hit", o.map.prob_hit, "P(occupied) of a cell a ray ends in");
  opt("--prob-miss", o.map.prob_miss, "P(occupied) of a cell a ray passes through");
  opt("--clamp-min", o.map.clamp_min, "Lower clamping probability");
  opt("--clamp-max", o.map.clamp_max, "Upper clamping probability");
  opt("--occupancy-threshold", o.map.occupancy_threshold, "Occupied when P >= this");
  opt("--decay-half-life", o.map.decay_half_life_s,
      "Forgetting: half-life of the evidence, s of sensor time (0 = off, OctoMap's behaviour)");
  opt("--decay-period", o.map.decay_period_s, "Forgetting: applied at most this often, s");
  opt("--forget-below", o.map.forget_below, "Forgetting: |log-odds| below which a cell becomes unknown");
  app.add_option("--stride", o.scan.stride,
                 "Depth decimation: every n-th pixel (5: 640x480 -> 128x96, 1: full resolution)")
      ->capture_default_str()
      ->group("Map");
  opt("--max-range", o.scan.max_range_m, "Readings beyond this only clear space, m");
  opt("--min-range", o.scan.min_range_m, "Readings nearer than this are ignored, m");
  app.add_flag("--discretize,!--no-discretize", o.scan.discretize,
               "Endpoint discretisation (OctoMap's insertPointCloud discretize=true): one ray per cell "
               "the readings end in, to its centre; else every reading's own ray")
      ->capture_default_str()
      ->group("Map");
  opt("--keyframe-megabytes", o.keyframes.max_megabytes, "Memory budget of the stored keyframes, MB");
  opt("--keyframe-bin-size", o.keyframes.bin_size_m, "Keyframe thinning: position bin, m");
  opt("--keyframe-bin-angle", o.keyframes.bin_angle_deg, "Keyframe thinning: view direction bin, deg");
  opt("--keyframe-translation", o.keyframe_translation_m, "Without SLAM: keep a keyframe every this much motion, m");
  opt("--keyframe-rotation", o.keyframe_rotation_deg, "... or this much rotation, deg");
  opt("--rebuild-translation", o.rebuild_translation_m, "A keyframe moved by more than this triggers a rebuild, m");
  opt("--rebuild-rotation", o.rebuild_rotation_deg, "... or by more than this, deg");
  opt("--rebuild-interval", o.rebuild_interval_s, "At most one rebuild per this much sensor time, s");
  app.add_option("--checkpoint-every", o.checkpoint_every,
                 "Rebuild checkpoints: a copy of the map every this many keyframes (0: none)")
      ->capture_default_str()
      ->group("Map");
  opt("--checkpoint-megabytes", o.checkpoint_megabytes, "Memory budget of the rebuild checkpoints, MB");
  opt("--frame-buffer", o.frame_buffer_s, "Frames kept for SLAM keyframes to refer to, s");
  app.add_option("--max-pinned-frames", o.max_pinned_frames,
                 "Frames kept past the buffer for keyframes SLAM made before placing the camera in its saved map")
      ->capture_default_str()
      ->group("Map");
}

namespace {

// validate()'s "key: why" as the option's usage error, "--key: why".
[[noreturn]] void throw_as_option_error(const std::invalid_argument& e) {
  const std::string what = e.what();
  const auto colon = what.find(':');
  throw CLI::ValidationError("--" + what.substr(0, colon), what.substr(colon == std::string::npos ? 0 : colon + 2));
}

}  // namespace

void check_mapper_options(const MapperOptions& o) {
  try {
    o.validate();
  } catch (const std::invalid_argument& e) {
    throw_as_option_error(e);
  }
}

void check_node_options(const NodeOptions& o) {
  try {
    o.validate();
  } catch (const std::invalid_argument& e) {
    throw_as_option_error(e);
  }
}

}  // namespace kestrel::mapper
