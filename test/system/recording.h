#pragma once
// What a system test's run recorded (the processes' outputs in the replay's --record log),
// and what the tests ask of the mapper's map: that it is the map of SLAM's keyframes at their
// true poses. The truth is carried into SLAM's world by the rigid fit of the keyframes'
// positions, so what is compared is the map's shape, not where SLAM's world happens to sit.

#include <Eigen/Geometry>
#include <cstdint>
#include <map>
#include <optional>
#include <string>

#include "common/rgbd_frame.h"
#include "common/trajectory.h"
#include "kestrel/slam_graph_t.hpp"

namespace kestrel::test {

struct Recording {
  std::map<int64_t, Eigen::Isometry3d> states;  ///< utime -> T_world_body (OK states)
  std::optional<kestrel::slam_graph_t> graph;   ///< the last one
  std::optional<Eigen::Isometry3d> T_body_camera;  ///< the first VO_UPDATE's
  int corrections = 0;                          ///< SLAM_CORRECTIONs
  int64_t last_map_revision = -1;  ///< MAP_OCTOMAP's (jumps to the next thousand after a rebuild)
};

/// The outputs in the log at `path`.
Recording read_recording(const std::string& path);

/// The CAMERA_RGBD frames of the log at `path` whose utimes are keys of `utimes`.
std::map<int64_t, RgbdFrame> read_frames(const std::string& path, const std::map<int64_t, Eigen::Isometry3d>& utimes);

/// Expects the map in `map_file` (kestrel-mapper --save) to agree with the map the library
/// builds, with the process's defaults, from the keyframes' frames in `source_log` at their
/// poses in `true_camera` (T_world_camera, interpolated at their depth images' times): at least
/// `min_agreement` of the cells both know in the same class, and as large a share of either
/// map's occupied cells within a cell of an occupied cell of the other.
void expect_map_agrees_with_truth(const kestrel::slam_graph_t& graph, const Trajectory& true_camera,
                                  const std::string& source_log, const std::string& map_file, double min_agreement);

}  // namespace kestrel::test
