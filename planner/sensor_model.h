#pragma once
// Sensor models for belief prediction: what a measurement at configuration q tells the filter.
//
// FeatureSensor observes the environment's point features that are within range, inside the
// field of view (centred on the vehicle's yaw, level), facing the sensor and in line of sight.
// Each gives z = (range, azimuth, elevation) with independent noise; its information
// H^T Q^-1 H (H = dz/dq, 3 x 4) goes through common/gaussian/information.h, so the planner and the
// filter share one definition of M. Presets cover the paper's three sensors:
//   paper_camera  2 m, 30 deg, range variance 1 m^2, bearing variance 1 rad^2 (§4 simulation)
//   kinect        4 m, 57 x 43 deg, range sigma 1.4e-3 d^2 m (Khoshelham), bearing 1e-3 rad
//   planar_laser  range-limited, 360 deg, range sigma 1 cm, bearing 0.5 deg
// Data association is perfect (as in the paper): visibility is decided at the mean.

#include <functional>
#include <vector>

#include "common/numbers.h"
#include "planner/environment.h"
#include "planner/types.h"

namespace kestrel::planner {

struct FeatureSensorOptions {
  double max_range_m = 2.0;
  double min_range_m = 0.3;
  double horizontal_fov_rad = 30.0 * kPi / 180.0;  ///< >= 2 pi: all round
  double vertical_fov_rad = 30.0 * kPi / 180.0;
  double range_sigma_m = 1.0;         ///< constant part of the range noise
  double range_sigma_per_m2 = 0.0;    ///< + this * d^2 (depth cameras)
  double bearing_sigma_rad = 1.0;     ///< azimuth and elevation

  static FeatureSensorOptions paper_camera();
  static FeatureSensorOptions kinect();
  static FeatureSensorOptions planar_laser(double range_m);
};

/// One visible feature's measurement: predicted z, Jacobian and noise variances.
struct FeatureMeasurement {
  Eigen::Vector3d z;                  ///< range (m), azimuth, elevation (rad; body-relative)
  Eigen::Matrix<double, 3, 4> H;      ///< dz/dq
  Eigen::Vector3d variances;          ///< diagonal of Q
};

class FeatureSensor {
 public:
  FeatureSensor(const Environment& env, FeatureSensorOptions options);

  const FeatureSensorOptions& options() const { return options_; }
  /// Indices of the features visible from q.
  std::vector<int> visible(const Config& q) const;
  /// The same by the definition alone (atan2 for every field-of-view test): the reference the
  /// fast path above is tested against (test FastVisibilityEqualsTheDefinition).
  std::vector<int> visible_reference(const Config& q) const;
  /// The measurement of feature `index` from q (no visibility check).
  FeatureMeasurement measure(const Config& q, int index) const;
  /// Predicted measurement of feature `index` from q, azimuth wrapped near `reference`.
  Eigen::Vector3d predict(const Config& q, int index, double reference_azimuth) const;
  /// One feature's H^T Q^-1 H: gaussian::measurement_information's values, for the diagonal Q.
  static Mat4 information_term(const FeatureMeasurement& m);
  /// EKF information M(q) = sum over visible features of H^T Q^-1 H.
  Mat4 information(const Config& q) const;
  /// UKF information gain I(q) = 1/2 log det(prior) - 1/2 log det(posterior) of one update of
  /// all visible features from `prior` (the paper's Algorithm 2, constant prior), via eq. 27.
  double ukf_information_gain(const Config& q, const Mat4& prior) const;
  /// The UKF's M of eq. 27 at q from `prior` (zero when nothing is visible).
  Mat4 ukf_information(const Config& q, const Mat4& prior) const;

 private:
  const Environment& env_;
  FeatureSensorOptions options_;
  // Features bucketed in square cells of max_range_m over x-y, so a query looks at 3 x 3 cells
  // (visible_reference).
  double cell_m_ = 1.0;
  Eigen::Vector2d cell_origin_ = Eigen::Vector2d::Zero();
  int nx_ = 0, ny_ = 0;
  std::vector<std::vector<int>> cells_;
  // visible(): cells of a quarter of the range, each a run of fine_ (feature index, position,
  // normal), so a query reads only the cells that meet the range's disc and the field of view's
  // wedge, and those contiguously.
  struct CellFeature {
    Eigen::Vector3d position;
    Eigen::Vector3d normal;
    int index;
  };
  double fine_m_ = 1.0;
  int fine_nx_ = 0, fine_ny_ = 0;
  std::vector<int> fine_start_;
  std::vector<CellFeature> fine_;
  // Field-of-view bounds a hair (kFovMargin_rad) outside and inside the edges: a feature
  // clearly outside or inside is decided by a dot product, only the band between by atan2.
  bool fast_azimuth_ = false, fast_elevation_ = false;
  double cos_h_out_ = 0.0, cos_h_in_ = 0.0, tan_v_out_ = 0.0, tan_v_in_ = 0.0;

  // H and Q of feature `index` from q without the predicted z (what M needs).
  void jacobian_and_noise(const Config& q, int index, FeatureMeasurement& m) const;
};

}  // namespace kestrel::planner
