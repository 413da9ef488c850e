// Per-frame cost of the Kinect driver's depth path: registering a raw 11-bit IR image to the
// RGB camera (what kestrel-kinect does for every frame on the vehicle, on one core), and the
// inverse that kestrel-tum-to-fakenect uses. Run: ./kestrel bench Registration (Release).

#include <benchmark/benchmark.h>

#include "drivers/kinect/depth_registration.h"

namespace {

using kestrel::kinect::DepthRegistration;
using kestrel::kinect::KinectCalibration;

// A room-like scene seen by the IR camera: a tilted wall 1.5 .. 4 m away, every pixel valid.
cv::Mat raw_scene(const KinectCalibration& c) {
  cv::Mat raw(480, 640, CV_16UC1);
  for (int v = 0; v < 480; ++v)
    for (int u = 0; u < 640; ++u) raw.at<uint16_t>(v, u) = c.disparity.raw(1.5 + 2.5 * u / 640.0 + 0.2 * v / 480.0);
  return raw;
}

void BM_RegisterRaw(benchmark::State& state) {
  const KinectCalibration c = state.range(0) ? KinectCalibration::standard()
                                             : KinectCalibration::identity(KinectCalibration::standard().rgb);
  const DepthRegistration reg(c);
  const cv::Mat raw = raw_scene(c);
  for (auto _ : state) benchmark::DoNotOptimize(reg.register_raw(raw).data);
}
BENCHMARK(BM_RegisterRaw)->Arg(0)->Arg(1)->ArgNames({"standard"})->Unit(benchmark::kMillisecond);

void BM_UnregisterMm(benchmark::State& state) {
  const KinectCalibration c = KinectCalibration::standard();
  const DepthRegistration reg(c);
  const cv::Mat mm = reg.register_raw(raw_scene(c));
  for (auto _ : state) benchmark::DoNotOptimize(reg.unregister_mm(mm).data);
}
BENCHMARK(BM_UnregisterMm)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
