// kestrel-map: builds the occupancy map offline from a TUM RGB-D folder and a trajectory
// (ground truth, VO, SLAM: any TUM-format file of T_world_camera), or from a mapper's journal
// (the keyframes of a flight, at the poses SLAM last gave them), writes it as .bt / .ot,
// and optionally renders it (top view, perspective, slice), exports the registered keyframes
// as a coloured PLY cloud, and compares it with another map. Same library as kestrel-mapper,
// no LCM. Prints what it did and how long the insertion took per frame (thread CPU time).

#include <spdlog/spdlog.h>

#include <algorithm>
#include <ctime>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/error.h"
#include "common/image/image_io.h"
#include "common/trajectory.h"
#include "drivers/tum/tum_sequence.h"
#include "mapper/cli_options.h"
#include "mapper/export_ply.h"
#include "mapper/keyframe_journal.h"
#include "mapper/map_compare.h"
#include "mapper/mapper.h"
#include "mapper/octree_io.h"
#include "mapper/render.h"
#include "mapper/scan.h"

namespace {

using namespace kestrel;

struct Options {
  std::string tum, poses, anchor, journal, out, png, view_png, slice_png, ply, compare;
  double slice_z_m = 1.0;
  double max_pose_gap_s = 0.05;
  double depth_scale = 1.0;
  size_t every = 1;
  bool surface_only = false;
  mapper::MapperOptions mapper;
  mapper::RenderOptions render;
};

void write_png(const std::string& path, const cv::Mat& image) {
  image::write_png(path, image);  // atomic: no cut image that looks whole
  std::cout << "wrote " << path << " (" << image.cols << "x" << image.rows << ")\n";
}

// CPU time of this thread: on a shared machine wall-clock time mostly measures the others.
double thread_cpu_ms() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return 1e3 * static_cast<double>(ts.tv_sec) + 1e-6 * static_cast<double>(ts.tv_nsec);
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  const size_t i = std::min(v.size() - 1, static_cast<size_t>(q * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(i), v.end());
  return v[i];
}

// `poses` moved rigidly so that its first pose coincides with `anchor`'s at the same time: a
// VO or SLAM trajectory that starts at the identity, placed in the ground truth's world frame
// (as if the estimator had been started at the true pose), with no further alignment.
Trajectory anchored(const Trajectory& poses, const Trajectory& anchor, const std::string& anchor_path) {
  const StampedPose& first = poses.poses().front();
  const auto T_world_first = anchor.at(first.utime, 50000);
  if (!T_world_first) throw InputError(anchor_path + ": no pose at the first pose's time");
  const Eigen::Isometry3d T_world_poses = *T_world_first * first.T.inverse();
  Trajectory out;
  for (const StampedPose& p : poses.poses()) out.push_back(p.utime, T_world_poses * p.T);
  return out;
}

// --surface-only: the cells holding a measured point within max range, occupied, and nothing
// else (no free space). With noiseless depth this is the true surface within sensor range,
// the reference for a map's voxel precision and recall.
void mark_surface(const RgbdFrame& frame, const Eigen::Isometry3d& T_world_camera,
                  const mapper::MapperOptions& o, mapper::VoxelMap& surface) {
  const mapper::Scan scan = mapper::make_scan(mapper::decimate(frame, o.scan.stride), T_world_camera, o.scan, "frame");
  for (size_t i = 0; i < scan.points.size(); ++i) {
    mapper::Key k;
    if (scan.valid[i] && (scan.points[i] - scan.origin).norm() <= o.scan.max_range_m &&
        surface.keys().key(scan.points[i], k))
      surface.set(k, surface.clamp_max());
  }
}

// The frames of a TUM folder at the poses of a trajectory, into `mapper` (or `surface`).
void map_sequence(const Options& o, mapper::Mapper& mapper, mapper::VoxelMap& surface) {
  tum::SequenceOptions so;
  so.depth_scale_correction = o.depth_scale;
  const tum::TumSequence sequence(o.tum, so);
  Trajectory poses = read_tum_trajectory(o.poses);
  if (poses.empty()) throw InputError(o.poses + ": no poses");
  if (!o.anchor.empty()) poses = anchored(poses, read_tum_trajectory(o.anchor), o.anchor);
  const int64_t max_gap = static_cast<int64_t>(o.max_pose_gap_s * 1e6);
  std::vector<double> ms;
  size_t without_pose = 0;
  for (size_t i = 0; i < sequence.size(); i += o.every) {
    const RgbdFrame frame = sequence.frame(i);
    const auto T_world_camera = poses.at(frame.depth_utime, max_gap);
    if (!T_world_camera) {
      ++without_pose;
      continue;
    }
    const double t0 = thread_cpu_ms();
    if (o.surface_only) {
      mark_surface(frame, *T_world_camera, o.mapper, surface);
    } else {
      mapper.insert(frame, *T_world_camera, sequence.folder().c_str());
    }
    ms.push_back(thread_cpu_ms() - t0);
  }
  if (ms.empty()) throw InputError(o.poses + ": no frame of " + o.tum + " has a pose within --max-pose-gap");
  std::printf("frames inserted: %zu (%zu without a pose), keyframes kept: %zu\n", ms.size(), without_pose,
              mapper.keyframes().size());
  std::printf("insertion (decimate + scan + cells + update), CPU ms per frame: median %.3f, p95 %.3f\n",
              percentile(ms, 0.5), percentile(ms, 0.95));
}

// The keyframes a mapper journalled, at their last poses (damaged records are left out, and said;
// the file is only read).
void map_journal(const Options& o, mapper::Mapper& mapper) {
  if (!std::filesystem::exists(o.journal)) throw InputError(o.journal + ": no such file");
  const mapper::JournalContents journal = mapper::read_journal(o.journal);
  if (journal.records.empty()) throw InputError(o.journal + ": no keyframes in the journal");
  if (!journal.damage.empty()) spdlog::warn("{}: damaged, every intact record read: {}", o.journal, journal.damage);
  const mapper::Restored restored = mapper::restore_journal(journal, mapper, o.journal);
  std::printf("keyframes restored from the journal: %lld, kept: %zu\n", static_cast<long long>(restored.keyframes),
              mapper.keyframes().size());
}

int run(Options& o) {
  mapper::check_mapper_options(o.mapper);
  mapper::format_of(o.out);  // a bad extension is an error before any work
  if (o.journal.empty() == o.tum.empty()) throw CLI::ValidationError("--tum/--journal", "give --tum with --poses, or --journal");
  if (!o.tum.empty() && o.poses.empty()) throw CLI::ValidationError("--poses", "--tum needs it");
  if (!o.journal.empty() && o.surface_only) throw CLI::ValidationError("--surface-only", "needs --tum");
  mapper::Mapper mapper(o.mapper);
  mapper::VoxelMap surface(o.mapper.map);
  if (o.journal.empty()) {
    map_sequence(o, mapper, surface);
  } else {
    map_journal(o, mapper);
  }
  const mapper::VoxelMap& map = o.surface_only ? surface : mapper.map();
  mapper::write_map_file(map, o.out);

  const double cell3 = map.resolution() * map.resolution() * map.resolution();
  const double volume = static_cast<double>(map.num_cells()) * cell3;
  std::printf("cells known: %zu (%.1f m^3), occupied: %zu; map memory %.2f MB (%.2f MB per 100 m^3)\n",
              map.num_cells(), volume, map.num_occupied(), map.memory_bytes() / 1e6,
              volume > 0 ? map.memory_bytes() / 1e6 * 100.0 / volume : 0.0);
  const double tree_mb = static_cast<double>(mapper::to_octree(map)->memoryUsage()) / 1e6;
  std::printf("as an OctoMap OcTree (pruned): %.2f MB (%.2f MB per 100 m^3)\n", tree_mb,
              volume > 0 ? tree_mb * 100.0 / volume : 0.0);
  std::cout << "wrote " << o.out << "\n";

  if (!o.png.empty()) write_png(o.png, mapper::render_top_view(map, o.render));
  if (!o.view_png.empty()) write_png(o.view_png, mapper::render_perspective(map, o.render));
  if (!o.slice_png.empty()) write_png(o.slice_png, mapper::render_slice(map, o.slice_z_m, o.render));
  if (!o.ply.empty()) {
    const size_t n = mapper::write_ply(mapper.keyframes(), o.ply, o.mapper.scan.max_range_m);
    std::cout << "wrote " << o.ply << " (" << n << " points from " << mapper.keyframes().size() << " keyframes)\n";
  }
  if (!o.compare.empty()) {
    const mapper::VoxelMap other = mapper::read_map_file(o.compare, o.mapper.map);
    const mapper::MapAgreement a = mapper::compare_maps(map, other);
    std::printf("against %s: class agreement %.4f on %zu cells known in both; occupied: %zu here, %zu there, "
                "%zu the same cell; within one cell: precision %.4f, recall %.4f\n",
                o.compare.c_str(), a.class_agreement(), a.known_both, a.occupied_a, a.occupied_b,
                a.occupied_both, a.precision(), a.recall());
    std::printf("  cells known here only %zu, there only %zu; free here and occupied there %zu, "
                "occupied here and free there %zu\n",
                a.known_a - a.known_both, a.known_b - a.known_both, a.free_a_occupied_b, a.occupied_a_free_b);
  }
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  cli::App app("map",
               "Build the occupancy map from a TUM RGB-D folder and a trajectory, or from a mapper's journal; "
               "write .bt/.ot, PNG renders, PLY");
  Options o;
  app.add_option("--tum", o.tum, "TUM RGB-D sequence folder (with --poses)");
  app.add_option("--poses", o.poses, "Trajectory of the camera, TUM format (ground truth or any estimate)");
  app.add_option("--journal", o.journal,
                 "Instead of --tum: a mapper's journal (kestrel mapper --journal; kestrel launch keeps it in "
                 "<log-dir>/run-*/mapper.journal)");
  app.add_option("--anchor", o.anchor,
                 "Trajectory (e.g. ground truth) whose pose at --poses' first time places --poses in its world");
  app.add_option("--out", o.out, "Map file to write (.bt binary or .ot full)")->required();
  app.add_option("--png", o.png, "Top view PNG (height-coloured)");
  app.add_option("--view-png", o.view_png, "Perspective view PNG");
  app.add_option("--slice-png", o.slice_png, "Horizontal slice PNG (see --slice-z)");
  app.add_option("--slice-z", o.slice_z_m, "Height of the slice, m")->capture_default_str();
  app.add_option("--ply", o.ply, "Coloured point cloud of the registered keyframes (PLY)");
  app.add_option("--compare", o.compare, "Report agreement with this map (.bt/.ot, same resolution)");
  app.add_option("--max-pose-gap", o.max_pose_gap_s, "Largest trajectory gap to interpolate across, s")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_option("--depth-scale", o.depth_scale, "Depth scale correction (fr1: about 1.035)")
      ->check(cli::Positive)
      ->capture_default_str();
  app.add_option("--every", o.every, "Insert every n-th frame")->check(CLI::Range(1, 1000))->capture_default_str();
  app.add_flag("--surface-only", o.surface_only,
               "Only mark the cells holding a point, occupied, no free space (a reference from noiseless depth)");
  app.add_option("--pixels-per-cell", o.render.pixels_per_cell, "Top view and slice scale")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  mapper::add_mapper_options(app, o.mapper);
  return app.run(argc, argv, [&] { return run(o); });
}
