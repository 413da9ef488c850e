#include "test/vo/synthetic_scene.h"

#include <cmath>
#include <random>
#include <sstream>

#include "drivers/sim/renderer.h"
#include "drivers/sim/world_file.h"

namespace kestrel::vo::test {
namespace {

// The scene's frame (x right, y down, z forward) in the world file's (x forward, y left,
// z up), with the room's corner at the world's origin: X = z + 1, Y = 2 - x, Z = 1.5 - y.
Eigen::Isometry3d T_sim_scene() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  T.translation() = Eigen::Vector3d(1.0, 2.0, 1.5);
  return T;
}

// The room as a world file: walls facing inwards (counter-clockwise outline), the back wall at
// X = depth + 1. Its surfaces are the simulator's most detailed patterns (book shelves on the
// walls, tiles above and below). What the seed places (a block standing in the room, for depth
// discontinuities and parallax, and two posters on the back wall, each one of a kind) makes two
// seeds two different places in texture and in geometry, a test's "another room": with the
// book shelves alone, two seeds were one texture shifted, which the matcher took for motion.
std::string room_world(unsigned seed, double depth_m) {
  const double X = depth_m + 1.0;
  std::mt19937 draw(seed);
  const auto uniform = [&](double lo, double hi) { return std::uniform_real_distribution<double>(lo, hi)(draw); };
  const double bx = uniform(0.45, 0.65) * depth_m + 1.0, by = uniform(1.2, 2.3), bh = uniform(1.0, 1.6);
  static const char* const kBlockPatterns[] = {"brick", "wood", "concrete"};
  const char* block_pattern = kBlockPatterns[draw() % 3];
  std::ostringstream posters;
  for (int i = 0; i < 2; ++i) {
    const double y0 = uniform(0.3, 2.5), z0 = uniform(0.4, 1.9);
    posters << "panel poster " << X - 0.01 << " " << y0 << " " << X - 0.01 << " " << y0 + 1.2 << " " << z0 << " "
            << z0 + 0.9 << "\n";
  }
  std::ostringstream w;
  w << "kestrel-world 1\n"
    << "name vo-test-room\n"
    << "seed " << seed << "\n"
    << "bounds 0 0 0 " << X << " 4 3\n"
    << "start 1 2 1.5 0\n"
    << "ambient 0.6\n"
    << "material floor    floor_tiles color 0.42 0.40 0.38 contrast 1.5\n"
    << "material ceiling  ceiling_tiles color 0.80 0.80 0.78 contrast 1.5\n"
    << "material back     books color 0.62 0.48 0.36 contrast 1.5\n"
    << "material poster   poster color 0.93 0.91 0.86 fit\n"
    << "material side     books color 0.66 0.65 0.62 contrast 1.5\n"
    << "material block    " << block_pattern << " color 0.55 0.38 0.22 contrast 1.5\n"
    << "floor   floor   0 0 " << X << " 4 0\n"
    << "ceiling ceiling 0 0 " << X << " 4 3\n"
    << "wall side 0 0 " << X << " 0\n"
    << "wall back " << X << " 0 " << X << " 4\n"
    << "wall side " << X << " 4 0 4\n"
    << "wall side 0 4 0 0\n"
    << "box block " << bx << " " << by << " 0 " << bx + 0.5 << " " << by + 0.7 << " " << bh << "\n"
    << posters.str()
    << "light " << 0.5 * X << " 1.3 2.9\n"
    << "light " << 0.5 * X << " 2.7 2.9\n";
  return w.str();
}

}  // namespace

PinholeCamera test_camera() {
  PinholeCamera c;
  c.width = 640;
  c.height = 480;
  c.fx = 517.3;
  c.fy = 516.5;
  c.cx = 318.6;
  c.cy = 255.3;
  return c;
}

SyntheticScene::SyntheticScene(unsigned seed, double depth_m)
    : seed_(seed),
      world_(std::make_unique<sim::World>(sim::parse_world(room_world(seed, depth_m), "vo test room"))) {}

SyntheticScene::~SyntheticScene() = default;

RgbdFrame SyntheticScene::render(const Eigen::Isometry3d& T_world_camera, const PinholeCamera& camera,
                                 int64_t utime) const {
  const auto same = [](const PinholeCamera& a, const PinholeCamera& b) {
    return a.width == b.width && a.height == b.height && a.fx == b.fx && a.fy == b.fy && a.cx == b.cx &&
           a.cy == b.cy;
  };
  if (!renderer_ || !renderer_camera_ || !same(*renderer_camera_, camera)) {
    sim::CameraOptions options;
    options.camera = camera;
    options.camera.distortion = {};  // a pinhole, as the header says
    options.near_m = 1e-3;
    options.depth.noise = false;
    options.rgb.noise = false;
    options.rgb.vignetting = 0.0;
    renderer_ = std::make_unique<sim::Renderer>(*world_, options, seed_);
    renderer_camera_ = camera;
  }
  RgbdFrame f = renderer_->render(T_sim_scene() * T_world_camera, utime, 0);
  // The exact depth, rather than the Kinect model's (quantised in disparity, with a range and
  // shadows): the tests compare against the geometry to the millimetre.
  const cv::Mat z = renderer_->ideal_depth();
  f.depth_mm.create(z.rows, z.cols, CV_16UC1);
  for (int y = 0; y < z.rows; ++y) {
    for (int x = 0; x < z.cols; ++x) {
      const float m = z.at<float>(y, x);
      f.depth_mm.at<uint16_t>(y, x) = m > 0.0f && m < 65.0f ? static_cast<uint16_t>(std::lround(1000.0 * static_cast<double>(m))) : 0;
    }
  }
  f.camera = camera;
  f.utime = utime;
  f.depth_utime = utime;
  f.T_body_camera = Eigen::Isometry3d::Identity();
  return f;
}

}  // namespace kestrel::vo::test
