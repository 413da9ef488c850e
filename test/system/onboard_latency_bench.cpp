// Onboard latency: a camera frame's arrival to the STATE that includes it, through the code the
// onboard processes run, on one thread. The frame arrives as the bytes of its CAMERA_RGBD
// message, as the simulator publishes it (JPEG colour at quality 95, zstd depth); then
// kestrel-vo's decode, VisualOdometry::process and the VO_UPDATE message, and kestrel-estimator's
// decode, StateEstimator::add_vo and the STATE message. The IMU samples between frames are fed
// untimed. Not in it: LCM's two loopback hops (about 0.1 ms each) and the scheduler.
//
// Data: 10 s of the synthetic room's figure-eight (300 frames, rendered once before timing).
// Counters: median_ms and p95_ms of the per-frame latency over the flight (the median of five
// flights). Run on one core: taskset -c 0 build/release/bench/onboard_latency_bench (Release).

#include <benchmark/benchmark.h>

#include <algorithm>
#include <chrono>
#include <memory>
#include <vector>

#include "common/transport/message.h"
#include "common/transport/rgbd_codec.h"
#include "drivers/sim/flights.h"
#include "drivers/sim/messages.h"
#include "drivers/sim/simulation.h"
#include "drivers/sim/world_catalog.h"
#include "estimator/messages.h"
#include "estimator/state_estimator.h"
#include "sensors/builtin_profiles.h"
#include "vo/sensor_profile.h"
#include "vo/update_message.h"
#include "vo/variants.h"

namespace {

using namespace kestrel;
using Clock = std::chrono::steady_clock;

struct Input {
  bool is_frame = false;
  std::vector<uint8_t> bytes;  // CAMERA_RGBD or IMU, encoded
};

const std::vector<Input>& flight() {
  static const std::vector<Input> inputs = [] {
    const sim::World world = sim::load_world("room");
    const auto path = sim::make_flight("figure8", world);
    sim::Simulation simulation(world, *path, sim::SimulationOptions{});
    transport::RgbdEncoding encoding;
    encoding.rgb = kestrel::rgbd_frame_t::RGB_JPEG;
    encoding.depth = kestrel::rgbd_frame_t::DEPTH_U16_MM_ZSTD;
    encoding.jpeg_quality = 95;  // the simulator's
    std::vector<Input> out;
    const int64_t end = simulation.next_utime() + 10'000'000;
    for (sim::SimEvent e = simulation.next(); e.utime <= end; e = simulation.next()) {
      if (e.kind == sim::SimEvent::kImu)
        out.push_back({false, transport::encode_message(sim::imu_message(e.utime, e.imu))});
      else
        out.push_back({true, transport::encode_message(transport::encode_rgbd(e.frame, encoding))});
    }
    return out;
  }();
  return inputs;
}

void BM_FrameToState(benchmark::State& state) {
  const std::vector<Input>& inputs = flight();
  const vo::VoOptions vo_options = vo::with_sensor(sensors::builtin_profile("simulator"), vo::variant("default").options);
  std::vector<double> medians, p95s;
  size_t frames = 0;
  for (auto _ : state) {
    vo::VisualOdometry odometry(vo_options);
    estimator::StateEstimator estimator(estimator::EstimatorOptions{});
    std::vector<double> ms;
    int64_t seq = 0;
    for (const Input& in : inputs) {
      if (!in.is_frame) {
        const auto imu = transport::decode_message<kestrel::imu_t>(in.bytes.data(), in.bytes.size(), "IMU");
        benchmark::DoNotOptimize(estimator.add_imu(estimator::imu_from_message(imu, "IMU")));
        continue;
      }
      const auto t0 = Clock::now();
      const auto message = transport::decode_message<kestrel::rgbd_frame_t>(in.bytes.data(), in.bytes.size(), "CAMERA_RGBD");
      const RgbdFrame frame = transport::decode_rgbd(message, "CAMERA_RGBD");
      const vo::VoResult r = odometry.process(frame);
      const std::vector<uint8_t> update = transport::encode_message(vo::to_message(r, frame.T_body_camera, 0.0));
      const auto vo_update = transport::decode_message<kestrel::vo_update_t>(update.data(), update.size(), "VO_UPDATE");
      const estimator::StepResult step = estimator.add_vo(estimator::vo_from_message(vo_update, "VO_UPDATE"));
      if (step.state) {
        const std::vector<uint8_t> out = transport::encode_message(
            estimator::state_to_message(*step.state, estimator.mode(), estimator::FilterKind::kEkf, seq++));
        benchmark::DoNotOptimize(out.data());
      }
      ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    }
    frames = ms.size();
    std::sort(ms.begin(), ms.end());
    medians.push_back(ms[ms.size() / 2]);
    p95s.push_back(ms[std::min(ms.size() - 1, ms.size() * 95 / 100)]);
  }
  std::sort(medians.begin(), medians.end());
  std::sort(p95s.begin(), p95s.end());
  state.counters["median_ms"] = medians[medians.size() / 2];
  state.counters["p95_ms"] = p95s[p95s.size() / 2];
  state.counters["frames"] = static_cast<double>(frames);
}

}  // namespace

BENCHMARK(BM_FrameToState)->Iterations(5)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
