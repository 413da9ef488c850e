// Text files a user gives: a TUM sequence's lists and ground truth, g2o pose graphs, world
// files, and every tool's INI configuration.

#include <iostream>
#include <sstream>

#include "common/cli.h"
#include "common/error.h"
#include "common/trajectory.h"
#include "drivers/sim/world_catalog.h"
#include "drivers/sim/world_file.h"
#include "drivers/tum/tum_lists.h"
#include "fuzz/groups.h"
#include "slam/posegraph/g2o_io.h"

namespace kestrel::fuzz {
namespace {

bool run_image_list(const uint8_t* data, size_t size) {
  return accepted([&] { tum::read_image_list(scratch_file("rgb.txt", data, size)); });
}
std::vector<Bytes> image_list_seeds() {
  return {text("# color images\n# file: 'rgbd_dataset_freiburg1_xyz.bag'\n# timestamp filename\n"
               "1305031102.175304 rgb/1305031102.175304.png\n1305031102.211214 rgb/1305031102.211214.png\n"),
          text("1305031102.160407 depth/1305031102.160407.png\n\n1305031102.194330 depth/1305031102.194330.png\n")};
}

bool run_accelerometer(const uint8_t* data, size_t size) {
  return accepted([&] { tum::read_accelerometer(scratch_file("accelerometer.txt", data, size)); });
}
std::vector<Bytes> accelerometer_seeds() {
  return {text("# accelerometer data\n# timestamp ax ay az\n1305031102.1732 -0.0848 -9.7922 0.2398\n"
               "1305031102.1837 -0.0726 -9.8044 0.2520\n"),
          text("# empty log\n")};
}

bool run_trajectory(const uint8_t* data, size_t size) {
  return accepted([&] { read_tum_trajectory(scratch_file("groundtruth.txt", data, size)); });
}
std::vector<Bytes> trajectory_seeds() {
  return {text("# ground truth trajectory\n# timestamp tx ty tz qx qy qz qw\n"
               "1305031098.6659 1.3563 0.6305 1.6380 0.6132 0.5962 -0.3311 -0.3986\n"
               "1305031098.6758 1.3543 0.6326 1.6367 0.6126 0.5966 -0.3321 -0.3978\n")};
}

// Both `kestrel posegraph` readings: as given, and with --repair-information.
bool run_g2o(const uint8_t* data, size_t size) {
  const std::string s(reinterpret_cast<const char*>(data), size);
  bool any = false;
  for (const bool repair : {false, true}) {
    any |= accepted([&] {
      std::istringstream in(s);
      slam::G2oReadOptions options;
      options.project_information = repair;
      slam::parse_g2o(in, "fuzz.g2o", nullptr, options);
    });
  }
  return any;
}
std::vector<Bytes> g2o_seeds() {
  return {text("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0.1\nVERTEX_SE2 2 2 0.1 0.2\n"
               "EDGE_SE2 0 1 1 0 0.1 500 0 0 500 0 5000\nEDGE_SE2 1 2 1 0.1 0.1 500 0 0 500 0 5000\n"
               "EDGE_SE2 0 2 2 0.1 0.3 100 0 0 100 0 1000\n"),
          text("VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\nVERTEX_SE3:QUAT 1 1 0 0 0 0 0.0499792 0.99875\n"
               "FIX 0\n"
               "EDGE_SE3:QUAT 0 1 1 0 0 0 0 0.0499792 0.99875 "
               "100 0 0 0 0 0 100 0 0 0 0 100 0 0 0 400 0 0 400 0 400\n")};
}

// Its geometry only: the appearance (textures, light maps) is made from the material
// catalogue, not from the file's bytes, and takes seconds per world at the fuzz build's -O1.
bool run_world(const uint8_t* data, size_t size) {
  return accepted([&] {
    const sim::World w = sim::parse_world(std::string(reinterpret_cast<const char*>(data), size), "fuzz.world",
                                          sim::WorldParts::kGeometry);
    const Eigen::Vector3d start = w.start().head<3>();
    // The first questions the sim and the planner ask of a world they load; parse_world has
    // already checked what a world must satisfy, so these must only not crash.
    static_cast<void>(w.inside(start));
    static_cast<void>(w.clearance(start));
  });
}
std::vector<Bytes> world_seeds() {
  std::vector<Bytes> out;
  for (const std::string& name : sim::builtin_world_names()) {
    if (const auto world = sim::builtin_world_text(name)) out.push_back(text(*world));
  }
  return out;
}

// A tool's configuration file: options of every kind the tools declare (a bounded number, a
// count, a choice, a list, a string, a flag), read with --config and printed with
// --print-config. A file is either taken (exit 0) or refused as a usage error (exit 2), and
// what it gives, printed and read back, prints the same again (common/cli.h).
int configure(const std::string& config_path, std::string& printed) {
  cli::App app("fuzz-config", "the options a kestrel tool declares");
  double rate = 30.0, scale = 1.0;
  int count = 4;
  std::string name = "room";
  int mode = 0;
  std::vector<double> offset{0.0, 0.0, 0.0};
  bool fast = false;
  app.add_option("--rate", rate, "Hz")->check(cli::Positive);
  app.add_option("--scale", scale, "a factor")->check(CLI::Range(0.0, 10.0));
  app.add_option("--count", count, "how many")->check(CLI::Range(1, 1000));
  app.add_option("--name", name, "a name");
  app.add_option("--mode", mode, "a choice")
      ->transform(CLI::CheckedTransformer(std::map<std::string, int>{{"ekf", 0}, {"ukf", 1}}));
  app.add_option("--offset", offset, "x y z")->expected(3);
  app.add_flag("--fast", fast, "a flag");
  const std::string tool = "kestrel-fuzz-config";
  std::vector<std::string> args{tool, "--config", config_path, "--print-config"};
  std::vector<char*> argv;
  for (std::string& a : args) argv.push_back(a.data());
  std::ostringstream out, err;
  auto* cout_buf = std::cout.rdbuf(out.rdbuf());
  auto* cerr_buf = std::cerr.rdbuf(err.rdbuf());
  const int code = app.run(static_cast<int>(argv.size()), argv.data(), [] { return 0; });
  std::cout.rdbuf(cout_buf);
  std::cerr.rdbuf(cerr_buf);
  printed = out.str();
  if (code != kExitOk && code != kExitUsage) defect("ini-config", "exit code " + std::to_string(code) + ": " + err.str());
  return code;
}

bool run_config(const uint8_t* data, size_t size) {
  std::string printed;
  if (configure(scratch_file("fuzz.ini", data, size), printed) != kExitOk) return false;
  std::string again;
  if (configure(scratch_file("printed.ini", printed), again) != kExitOk) {
    defect("ini-config", "a printed configuration is refused when read back:\n" + printed);
  }
  if (again != printed) defect("ini-config", "a configuration read back prints differently:\n" + printed + "---\n" + again);
  return true;
}
std::vector<Bytes> config_seeds() {
  return {text("rate = 15\nscale = 2.5\ncount = 8\nname = \"office, north\"\nmode = ukf\noffset = [0.1, -0.2, 1]\nfast\n"),
          text("# only some\n; comments\nname = 'raw \\x41'\noffset = [1,\n  2, 3]\n")};
}

}  // namespace

std::vector<Target> text_targets() {
  return {
      {"tum-image-list", "a TUM rgb.txt / depth.txt", &run_image_list, &image_list_seeds},
      {"tum-accelerometer", "a TUM accelerometer.txt", &run_accelerometer, &accelerometer_seeds},
      {"tum-trajectory", "a TUM groundtruth.txt (or any TUM trajectory eval reads)", &run_trajectory, &trajectory_seeds},
      {"g2o", "a g2o pose graph, as kestrel posegraph reads it", &run_g2o, &g2o_seeds},
      {"world", "a simulator world file", &run_world, &world_seeds},
      {"ini-config", "a tool's --config file", &run_config, &config_seeds},
  };
}

}  // namespace kestrel::fuzz
