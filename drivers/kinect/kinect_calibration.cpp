#include "drivers/kinect/kinect_calibration.h"

#include <stdexcept>

#include "common/error.h"

namespace kestrel::kinect {

KinectCalibration KinectCalibration::standard() {
  KinectCalibration c;
  c.rgb = PinholeCamera::vga(5.2921508098293293e+02, 5.2556393630057437e+02, 3.2894272028759258e+02,
                                2.6748068171871557e+02);
  c.ir = PinholeCamera::vga(5.9421434211923247e+02, 5.9104053696870778e+02, 3.3930780975300314e+02,
                               2.4273913761751615e+02);
  Eigen::Matrix3d R;
  R << 9.9984628826577793e-01, 1.2635359098409581e-03, -1.7487233004436643e-02,
      -1.4779096108364480e-03, 9.9992385683542895e-01, -1.2251380107679535e-02,
      1.7470421412464927e-02, 1.2275341476520762e-02, 9.9977202419716948e-01;
  const Eigen::Vector3d t(1.9985242312092553e-02, -7.4423738761617583e-04, -1.0916736334336222e-02);
  c.T_ir_rgb = make_rigid(R, t);
  return c;
}

KinectCalibration KinectCalibration::identity(const PinholeCamera& camera) {
  KinectCalibration c;
  c.rgb = camera;
  c.ir = camera;
  return c;
}

void KinectCalibration::validate() const {
  try {
    rgb.validate("RGB camera");
    ir.validate("IR camera");
  } catch (const InputError& e) {
    throw std::invalid_argument(e.what());
  }
  make_rigid(T_ir_rgb.linear(), T_ir_rgb.translation());
  disparity.validate();
}

Eigen::Isometry3d make_rigid(const Eigen::Matrix3d& R, const Eigen::Vector3d& t) {
  if (!R.allFinite() || !t.allFinite()) throw std::invalid_argument("IR-RGB transform is not finite");
  if (!(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || R.determinant() < 0.0)
    throw std::invalid_argument("IR-RGB rotation is not a rotation matrix");
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
  T.translation() = t;
  return T;
}

}  // namespace kestrel::kinect
