// The estimator fed a stream of inputs, as its process feeds it: IMU samples, VO updates and
// SLAM corrections in any order, with any values and any time stamps (jumps forward and back).
// Its gates (estimator/input_gate.h) must keep every state it publishes finite, with a
// covariance whose variances are finite and not negative, whatever arrives.

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>

#include "estimator/state_estimator.h"
#include "fuzz/groups.h"

namespace kestrel::fuzz {
namespace {

// A record: kind (bits 0-1: IMU, VO, correction; bit 6: the time jumps ahead by dt seconds;
// bit 7: back by dt milliseconds), dt (u16, little-endian: microseconds since the last record
// otherwise), six doubles (raw little-endian bytes, so NaN, infinities and 1e300 are reachable).
constexpr size_t kRecordSize = 1 + 2 + 6 * 8;

struct Record {
  uint8_t kind;
  uint16_t dt;
  double v[6];
};

Record record_at(const uint8_t* p) {
  Record r{};
  r.kind = p[0];
  r.dt = static_cast<uint16_t>(p[1] | (p[2] << 8));
  std::memcpy(r.v, p + 3, sizeof r.v);
  return r;
}

void put(Bytes& out, uint8_t kind, uint16_t dt, const double (&v)[6]) {
  out.push_back(kind);
  out.push_back(static_cast<uint8_t>(dt & 0xff));
  out.push_back(static_cast<uint8_t>(dt >> 8));
  const auto* b = reinterpret_cast<const uint8_t*>(v);
  out.insert(out.end(), b, b + sizeof v);
}

void check(const estimator::EstimatorOutput& s) {
  if (!s.nav.all_finite()) defect("estimator-stream", "a published state is not finite");
  if (!s.covariance.allFinite() || (s.covariance.diagonal().array() < 0.0).any()) {
    defect("estimator-stream", "a published covariance has a non-finite or negative variance");
  }
}

bool run_stream(const uint8_t* data, size_t size) {
  estimator::StateEstimator estimator{estimator::EstimatorOptions{}};
  int64_t utime = 1'000'000, last_vo = 0;
  int64_t revision = 0;
  bool published = false;
  for (size_t at = 0; at + kRecordSize <= size; at += kRecordSize) {
    const Record r = record_at(data + at);
    if (r.kind & 0x80) utime -= 1000 * static_cast<int64_t>(r.dt);
    else if (r.kind & 0x40) utime += 1'000'000 * static_cast<int64_t>(r.dt);
    else utime += r.dt;
    std::optional<estimator::EstimatorOutput> state;
    switch (r.kind & 0x03) {
      case 0: {
        estimator::ImuReading m;
        m.utime = utime;
        m.gyro = Eigen::Vector3d(r.v[0], r.v[1], r.v[2]);
        m.accel = Eigen::Vector3d(r.v[3], r.v[4], r.v[5]);
        state = estimator.add_imu(m).state;
        break;
      }
      case 1: {
        estimator::VoUpdate u;
        u.utime = utime;
        u.reference_utime = last_vo > 0 ? last_vo : utime - 33'333;
        u.ok = true;
        const Eigen::Vector3d w(r.v[3], r.v[4], r.v[5]);
        const double angle = w.norm();
        u.T_refcam_curcam = Eigen::Translation3d(r.v[0], r.v[1], r.v[2]) *
                            (angle > 0.0 ? Eigen::AngleAxisd(angle, w / angle) : Eigen::AngleAxisd::Identity());
        u.covariance = Matrix6d::Identity() * 1e-6;
        state = estimator.add_vo(u).state;
        last_vo = utime;
        break;
      }
      default: {
        estimator::PoseCorrection c;
        c.utime = last_vo > 0 ? last_vo : utime;
        c.revision = ++revision;
        c.T_world_body = Eigen::Translation3d(r.v[0], r.v[1], r.v[2]) * Eigen::AngleAxisd(r.v[3], Eigen::Vector3d::UnitZ());
        c.covariance = Matrix6d::Identity() * 1e-4;
        estimator.add_correction(c);
        state = estimator.output();
        break;
      }
    }
    if (state) {
      check(*state);
      published = true;
    }
  }
  return published;
}

// A second at rest: the IMU at 200 Hz reading gravity, VO at 30 Hz seeing no motion, one SLAM
// correction where the vehicle is.
std::vector<Bytes> stream_seeds() {
  Bytes out;
  const double imu[6] = {0.001, -0.002, 0.0005, 0.02, -0.01, 9.81};
  const double still[6] = {0, 0, 0, 0, 0, 0};
  for (int i = 1; i <= 200; ++i) {
    put(out, 0, 5000, imu);
    if (i % 7 == 0) put(out, 1, 0, still);
    if (i == 150) put(out, 2, 0, still);
  }
  return {out};
}

}  // namespace

std::vector<Target> estimator_targets() {
  return {{"estimator-stream", "IMU, VO and SLAM corrections in any order and timing, as the estimator takes them",
           &run_stream, &stream_seeds}};
}

}  // namespace kestrel::fuzz
