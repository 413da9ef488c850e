// Insertion speed: kestrel's exact cell search against OcTree::insertPointCloud on the same
// rays, and kestrel's endpoint-discretised insertion against insertPointCloud(..., discretize =
// true), in one run, one thread (Release). Frames: every 10th frame of the real fr1_xyz sequence
// at its ground-truth poses (or the synthetic room of the tests when ../shared/data is absent),
// at 128x96 (stride 5, the paper's size) and 640x480 (stride 1), 10 cm, max range 4 m.
//
// Each iteration inserts the next frame into a map that keeps growing, as a mapper does.
// "Insert" is the whole update (decimated frame -> rays -> cells -> log-odds); "Cells" is the
// cell computation alone; "Octomap" is the insertPointCloud call alone (/exact: every ray,
// /discretized: discretize = true; its own rays in, its tree updated and pruned), i.e. the
// comparison favours OctoMap. "/arrived" variants time a frame (or cloud) just copied into a
// working buffer, as a running mapper inserts what it has just decoded. The rebuild benchmark times
// a loop closure (Mapper::apply_graph moving the last quarter of the keyframes), without and
// with the rebuild's checkpoints.
//
// Run: ./kestrel bench mapper   (or build/<dir>/bench/mapper_bench --benchmark_repetitions=5)

#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>
#include <octomap/OcTree.h>

#include "drivers/tum/tum_sequence.h"
#include "mapper/mapper.h"
#include "mapper/scan.h"
#include "mapper/scan_integrator.h"
#include "test/mapper/scene.h"

namespace {

using namespace kestrel;
using namespace kestrel::mapper;

struct Frames {
  std::vector<RgbdFrame> frames;
  std::vector<Eigen::Isometry3d> poses;
  std::string source;
};

const Frames& frames() {
  static const Frames f = [] {
    Frames out;
    const std::filesystem::path dir = std::filesystem::path(KESTREL_SHARED_DATA) / "tum/rgbd_dataset_freiburg1_xyz";
    if (std::filesystem::exists(dir / "rgb.txt")) {
      const tum::TumSequence seq(dir.string());
      for (size_t i = 0; i < seq.size(); i += 10) {
        const RgbdFrame frame = seq.frame(i);
        const auto T = seq.ground_truth().at(frame.depth_utime, 50000);
        if (!T) continue;
        out.frames.push_back(frame);
        out.poses.push_back(*T);
      }
      out.source = "fr1_xyz, every 10th frame, ground truth";
    } else {
      test::Scene scene(Eigen::Vector3d(-2.0, -2.0, 0.0), Eigen::Vector3d(3.0, 2.0, 2.5));
      scene.add_box(Eigen::Vector3d(0.8, -0.4, 0.0), Eigen::Vector3d(1.4, 0.3, 0.9));
      for (int i = 0; i < 40; ++i) {
        const Eigen::Isometry3d T = test::look_at({-1.2 + 0.02 * i, 0.013, 1.2}, {2.0, 0.5 - 0.025 * i, 0.7});
        out.frames.push_back(scene.render(test::kinect_camera(), T, 1000 + 33333 * i));
        out.poses.push_back(T);
      }
      out.source = "synthetic room (../shared/data absent)";
    }
    return out;
  }();
  return f;
}

std::vector<Scan> scans(int stride) {
  ScanOptions o;
  o.stride = stride;
  std::vector<Scan> out;
  for (size_t i = 0; i < frames().frames.size(); ++i)
    out.push_back(make_scan(decimate(frames().frames[i], stride), frames().poses[i], o, "bench"));
  return out;
}

// Mapper::insert as a mapper calls it per frame: the scan, the cells, the log-odds and, when
// the camera moved far enough (about every third frame here), the keyframe's decimated copy
// (colour and depth, kept for rebuilds). /no_keyframes: the same with keyframe storage off (only
// the first frame is stored), to show what the copy costs.
// /arrived: each frame is first copied into one working frame outside the timed region, as a
// mapper receives it (decoded from its message, or read from its file, just before the
// insertion), so its depth comes from the cache rather than from memory. Without it the 80
// cycled frames (~120 MB) are cold while OctoMap's prepared clouds (~9 MB) stay in L3.
void BM_Insert(benchmark::State& state, bool discretize, bool keyframes = true, bool arrived = false) {
  MapperOptions o;
  o.scan.stride = static_cast<int>(state.range(0));
  o.scan.discretize = discretize;
  if (!keyframes) {
    o.keyframe_translation_m = 1e9;
    o.keyframe_rotation_deg = 180.0;
  }
  Mapper mapper(o);
  const Frames& f = frames();
  size_t i = 0;
  RgbdFrame working = f.frames.front();
  working.rgb = f.frames.front().rgb.clone();
  working.depth_mm = f.frames.front().depth_mm.clone();
  for (auto _ : state) {
    const RgbdFrame& next = f.frames[i % f.frames.size()];
    if (arrived) {
      state.PauseTiming();
      next.rgb.copyTo(working.rgb);
      next.depth_mm.copyTo(working.depth_mm);
      working.utime = next.utime;
      working.depth_utime = next.depth_utime;
      working.seq = next.seq;
      state.ResumeTiming();
    }
    mapper.insert(arrived ? working : next, f.poses[i % f.frames.size()]);
    ++i;
  }
  state.SetLabel(f.source);
  state.counters["occupied"] = static_cast<double>(mapper.map().num_occupied());
  state.counters["keyframes"] = static_cast<double>(mapper.keyframes().size()) / static_cast<double>(i);
}

void BM_Cells(benchmark::State& state, ScanIntegrator::Method method) {
  const std::vector<Scan> s = scans(static_cast<int>(state.range(0)));
  ScanOptions o;
  o.stride = static_cast<int>(state.range(0));
  ScanIntegrator integrator(0.1, o);
  ScanUpdate update;
  size_t i = 0;
  double rays = 0, free = 0, occupied = 0, tested = 0, witnessed = 0, traced = 0, tests = 0;
  for (auto _ : state) {
    integrator.compute(s[i++ % s.size()], update, method);
    rays += update.rays;
    free += update.free.size();
    occupied += update.occupied.size();
    tested += update.cells_tested;
    witnessed += update.cells_witnessed;
    traced += update.rays_traced;
    tests += update.ray_tests;
  }
  const double n = static_cast<double>(i);
  state.counters["rays"] = rays / n;
  state.counters["free"] = free / n;
  state.counters["occ"] = occupied / n;
  state.counters["tested"] = tested / n;
  state.counters["witnessed"] = witnessed / n;
  state.counters["traced"] = traced / n;
  state.counters["tests"] = tests / n;
}

// /arrived: as BM_Insert's, the cloud copied into one working cloud outside the timed region.
void BM_Octomap(benchmark::State& state, bool discretize, bool arrived = false) {
  const std::vector<Scan> s = scans(static_cast<int>(state.range(0)));
  std::vector<octomap::Pointcloud> clouds;
  for (const Scan& scan : s) clouds.push_back(scan.valid_points());
  octomap::OcTree tree(0.1);
  octomap::Pointcloud working;
  size_t i = 0;
  for (auto _ : state) {
    const size_t k = i++ % s.size();
    if (arrived) {
      state.PauseTiming();
      working.clear();
      working.push_back(clouds[k]);
      state.ResumeTiming();
    }
    tree.insertPointCloud(arrived ? working : clouds[k], s[k].origin, 4.0, false, discretize);
  }
  state.SetLabel(frames().source);
}

// A loop closure that moves the last quarter of the keyframes (alternately by +-3 cm, through
// apply_graph as SLAM would), arg 1: with checkpoints (every 4 keyframes), arg 0: without
// (every rebuild starts from nothing).
void BM_Rebuild(benchmark::State& state) {
  MapperOptions o;
  o.keyframe_translation_m = 0.0;  // every frame is a keyframe
  o.keyframe_rotation_deg = 0.0;
  o.rebuild_interval_s = 0.0;
  o.checkpoint_every = state.range(0) ? 4 : 0;
  Mapper mapper(o);
  const Frames& f = frames();
  for (size_t i = 0; i < f.frames.size(); ++i) mapper.insert(f.frames[i], f.poses[i]);
  std::vector<GraphKeyframe> graph;
  for (const StoredKeyframe* kf : mapper.keyframes().in_stored_order())
    graph.push_back({kf->id, kf->utime, kf->T_world_camera});
  mapper.rebuild();  // the first rebuild takes the checkpoints
  const size_t moved_from = graph.size() - graph.size() / 4;
  double reinserted = 0, n = 0;
  for (auto _ : state) {
    const double dx = static_cast<int>(n) % 2 ? -0.03 : 0.03;
    for (size_t i = moved_from; i < graph.size(); ++i) graph[i].T_world_camera.translation().x() += dx;
    reinserted += static_cast<double>(mapper.apply_graph(graph).reinserted);
    ++n;
  }
  state.counters["keyframes"] = static_cast<double>(graph.size());
  state.counters["reinserted"] = reinserted / n;
}

BENCHMARK_CAPTURE(BM_Insert, exact, false)->Arg(5)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Insert, discretized, true)->Arg(5)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Insert, exact_no_keyframes, false, false)->Arg(5)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Insert, discretized_no_keyframes, true, false)->Arg(5)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Insert, exact_arrived, false, true, true)->Arg(5)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Insert, discretized_arrived, true, true, true)->Arg(5)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Insert, discretized_no_keyframes_arrived, true, false, true)->Arg(5)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Cells, cell_search, ScanIntegrator::Method::kCellSearch)->Arg(5)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Cells, ray_trace, ScanIntegrator::Method::kRayTrace)->Arg(5)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Cells, discretized, ScanIntegrator::Method::kDiscretized)->Arg(5)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Octomap, exact, false)->Arg(5)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Octomap, discretized, true)->Arg(5)->Arg(1)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Octomap, exact_arrived, false, true)->Arg(5)->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Octomap, discretized_arrived, true, true)->Arg(5)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Rebuild)->Arg(0)->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
