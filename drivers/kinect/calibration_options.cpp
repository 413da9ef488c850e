#include "drivers/kinect/calibration_options.h"

#include <sstream>
#include <stdexcept>

namespace kestrel::kinect {
namespace {

std::vector<double> intrinsics_of(const PinholeCamera& c) { return {c.fx, c.fy, c.cx, c.cy}; }

PinholeCamera camera_of(const std::vector<double>& v, const char* option) {
  PinholeCamera c;  // 640x480, like every Kinect v1 stream driven here
  c.fx = v[0];
  c.fy = v[1];
  c.cx = v[2];
  c.cy = v[3];
  try {
    c.validate(option);
  } catch (const std::exception&) {
    throw CLI::ValidationError(option, "needs fx,fy > 0 and finite values");
  }
  return c;
}

// The default as "[a,b,...]" with 12 significant digits: CLI11's own default string has 6,
// which --print-config would hand back as a silently rounded calibration.
CLI::Option* add_list(CLI::App& app, const char* name, std::vector<double>& v, int n, const char* help) {
  std::ostringstream text;
  text.precision(12);
  text << '[';
  for (size_t i = 0; i < v.size(); ++i) text << (i ? "," : "") << v[i];
  text << ']';
  return app.add_option(name, v, help)->expected(n)->delimiter(',')->default_str(text.str());
}

}  // namespace

void CalibrationOptions::add_to(CLI::App& app) {
  const KinectCalibration d = KinectCalibration::standard();
  rgb_intrinsics = intrinsics_of(d.rgb);
  ir_intrinsics = intrinsics_of(d.ir);
  const Eigen::Matrix3d R = d.T_ir_rgb.linear();
  rotation.clear();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) rotation.push_back(R(r, c));
  translation = {d.T_ir_rgb.translation().x(), d.T_ir_rgb.translation().y(), d.T_ir_rgb.translation().z()};
  disparity = {d.disparity.a, d.disparity.b};

  add_list(app, "--rgb-intrinsics", rgb_intrinsics, 4, "RGB camera fx,fy,cx,cy (pixels)");
  add_list(app, "--ir-intrinsics", ir_intrinsics, 4, "IR (depth) camera fx,fy,cx,cy (pixels)");
  add_list(app, "--rgb-in-ir-rotation", rotation, 9,
           "Rotation of T_ir_rgb (RGB-camera points into the IR camera), row-major");
  add_list(app, "--rgb-in-ir-translation", translation, 3, "Translation of T_ir_rgb, metres");
  add_list(app, "--disparity", disparity, 2, "Raw depth model z = 1 / (a raw + b): a,b in 1/m");
  app.add_flag("--identity-calibration", identity,
               "IR camera = RGB camera and no offset (depth already registered)");
}

KinectCalibration CalibrationOptions::calibration() const {
  KinectCalibration c;
  c.rgb = camera_of(rgb_intrinsics, "--rgb-intrinsics");
  if (identity) {
    c.ir = c.rgb;
  } else {
    c.ir = camera_of(ir_intrinsics, "--ir-intrinsics");
    Eigen::Matrix3d R;
    for (int r = 0; r < 3; ++r)
      for (int col = 0; col < 3; ++col) R(r, col) = rotation[static_cast<size_t>(3 * r + col)];
    try {
      c.T_ir_rgb = make_rigid(R, Eigen::Vector3d(translation[0], translation[1], translation[2]));
    } catch (const std::invalid_argument& e) {
      throw CLI::ValidationError("--rgb-in-ir-rotation/--rgb-in-ir-translation", e.what());
    }
  }
  c.disparity.a = disparity[0];
  c.disparity.b = disparity[1];
  try {
    c.disparity.validate();
  } catch (const std::invalid_argument& e) {
    throw CLI::ValidationError("--disparity", e.what());
  }
  return c;
}

}  // namespace kestrel::kinect
