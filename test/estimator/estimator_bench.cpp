// Speed of the estimator against the targets (Release, one core, medians):
// IMU propagation <= 5 us per sample, VO update <= 100 us, a SLAM correction with 2 s of
// re-propagation <= 2 ms. Inputs: the aggressive analytic motion, a 200 Hz IMU with noise and
// the synthetic VO at 30 Hz, so the state carries the clones it carries in flight.
// Run: build/<dir>/bench/estimator_bench --benchmark_repetitions=5 --benchmark_report_aggregates_only

#include <benchmark/benchmark.h>

#include "estimator/estimator.h"
#include "estimator/eval/synthetic_vo.h"
#include "test/estimator/analytic_motion.h"

namespace kestrel::estimator {
namespace {

constexpr double kImuRate = 200.0;

struct Flight {
  test::ImuRecord imu;
  std::vector<VoUpdate> vo;  // one per 30 Hz frame, delivered 30 ms late
};

const Flight& flight() {
  static const Flight recorded = [] {
    Flight f;
    const auto motion = test::AnalyticMotion::aggressive();
    f.imu = test::generate_imu(motion, kImuRate, 60.0, test::ImuNoiseTruth{}, 3);
    SyntheticVo vo(SyntheticVoOptions{}, 4);
    for (int64_t t = 1000000 + 1667; t < f.imu.samples.back().utime; t += 33333)
      f.vo.push_back(vo.next(t, motion.state(test::seconds(t)).T_world_body()));
    return f;
  }();
  return recorded;
}

// Runs an estimator over the first `seconds` of the flight (IMU and VO as they arrive).
void fly(Estimator& e, size_t& imu_i, size_t& vo_i, double seconds) {
  const Flight& f = flight();
  const auto motion = test::AnalyticMotion::aggressive();
  if (!e.initialized()) {
    Matrix15d P = Matrix15d::Identity() * 1e-4;
    e.initialize(motion.state(0.0), P, f.imu.samples[0]);
    imu_i = 1;
  }
  const int64_t until = f.imu.samples[imu_i].utime + static_cast<int64_t>(seconds * 1e6);
  for (; imu_i < f.imu.samples.size() && f.imu.samples[imu_i].utime < until; ++imu_i) {
    const ImuSample& s = f.imu.samples[imu_i];
    while (vo_i < f.vo.size() && f.vo[vo_i].utime + 30000 <= s.utime) e.add_vo(f.vo[vo_i++]);
    e.add_imu(s);
  }
}

// One IMU sample handed to the estimator in steady flight (propagation, snapshot, trimming),
// VO arriving between samples as in flight but outside the timed region.
void BM_ImuSample(benchmark::State& state) {
  EstimatorOptions o;
  o.filter = static_cast<FilterKind>(state.range(0));
  Estimator e(o);
  size_t imu_i = 0, vo_i = 0;
  fly(e, imu_i, vo_i, 4.0);
  const Flight& f = flight();
  for (auto _ : state) {
    if (imu_i + 1 >= f.imu.samples.size()) {
      state.PauseTiming();
      e.reset();
      imu_i = vo_i = 0;
      fly(e, imu_i, vo_i, 4.0);
      state.ResumeTiming();
    }
    const ImuSample& s = f.imu.samples[imu_i++];
    if (vo_i < f.vo.size() && f.vo[vo_i].utime + 30000 <= s.utime) {
      state.PauseTiming();
      while (vo_i < f.vo.size() && f.vo[vo_i].utime + 30000 <= s.utime) e.add_vo(f.vo[vo_i++]);
      state.ResumeTiming();
    }
    benchmark::DoNotOptimize(e.add_imu(s));
  }
}
BENCHMARK(BM_ImuSample)->Arg(0)->ArgName("ukf")->Arg(1);

// The filter's share of an IMU sample: one prediction of mean and covariance on the state
// of steady flight (with its clones).
void BM_Predict(benchmark::State& state) {
  const auto kind = static_cast<FilterKind>(state.range(0));
  EstimatorOptions o;
  o.filter = kind;
  Estimator e(o);
  size_t imu_i = 0, vo_i = 0;
  fly(e, imu_i, vo_i, 4.0);
  const FilterState start = *e.filter_state();
  const auto filter = make_filter(kind, o.imu, o.gravity, o.unscented);
  ImuInterval u;
  u.dt = 1.0 / kImuRate;
  u.gyro0 = u.gyro1 = flight().imu.samples[imu_i].gyro;
  u.accel0 = u.accel1 = flight().imu.samples[imu_i].accel;
  for (auto _ : state) {
    FilterState s = start;
    filter->predict(s, u);
    benchmark::DoNotOptimize(s.P.data());
  }
  state.counters["state_dim"] = start.mean.dim();
}
BENCHMARK(BM_Predict)->Arg(0)->ArgName("ukf")->Arg(1);

// One filter update with a VO measurement against a cloned keyframe (the state holds the
// clones of steady flight), without the replay the estimator adds around it.
void BM_VoUpdate(benchmark::State& state) {
  const auto kind = static_cast<FilterKind>(state.range(0));
  EstimatorOptions o;
  o.filter = kind;
  Estimator e(o);
  size_t imu_i = 0, vo_i = 0;
  fly(e, imu_i, vo_i, 4.0);
  const FilterState start = *e.filter_state();
  const auto filter = make_filter(kind, o.imu, o.gravity, o.unscented);
  const Clone& ref = start.mean.clones[0];
  Eigen::Isometry3d T_ref = Eigen::Isometry3d::Identity();
  T_ref.linear() = ref.R_world_body;
  T_ref.translation() = ref.p_world_body;
  const Eigen::Isometry3d z = T_ref.inverse() * start.mean.nav.T_world_body();
  const RelativePoseMeasurement m(0, z, Matrix6d::Identity() * 1e-4, Eigen::Isometry3d::Identity());
  for (auto _ : state) {
    FilterState s = start;
    benchmark::DoNotOptimize(filter->update(s, m, 30.0));
  }
  state.counters["state_dim"] = start.mean.dim();
}
BENCHMARK(BM_VoUpdate)->Arg(0)->ArgName("ukf")->Arg(1);

// A SLAM correction for 2 s ago: applied there and the 400 IMU steps (with their VO
// updates) since re-propagated. Each iteration sends a newer revision for the same time.
void BM_LateCorrection2s(benchmark::State& state) {
  EstimatorOptions o;
  o.filter = static_cast<FilterKind>(state.range(0));
  Estimator e(o);
  size_t imu_i = 0, vo_i = 0;
  fly(e, imu_i, vo_i, 4.0);
  PoseCorrection c;
  c.utime = flight().imu.samples[imu_i - 1].utime - 2000000 + 1234;
  c.T_world_body = test::AnalyticMotion::aggressive().state(test::seconds(c.utime)).T_world_body();
  const EstimatorCounters before = e.counters();
  for (auto _ : state) {
    ++c.revision;
    benchmark::DoNotOptimize(e.add_correction(c));
  }
  const EstimatorCounters after = e.counters();
  state.counters["replayed_steps"] = static_cast<double>(after.replayed_steps - before.replayed_steps) /
                                     static_cast<double>(after.replays - before.replays);
}
BENCHMARK(BM_LateCorrection2s)->Arg(0)->ArgName("ukf")->Arg(1)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace kestrel::estimator

BENCHMARK_MAIN();
