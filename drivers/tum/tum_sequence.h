#pragma once
// A TUM RGB-D sequence folder as a list of RGB-D frames, for every offline tool (player, VO,
// SLAM and mapper evaluations) to iterate.
//
// The folder holds rgb.txt and depth.txt (required), groundtruth.txt and accelerometer.txt
// (optional: TUM's validation sequences have no ground truth), and the PNGs they list. On
// construction all text files are read and checked, every listed image is checked to exist,
// and each RGB frame takes the nearest depth frame within the tolerance (association.h; a depth
// frame may serve two); at least one pair must result. Images are only
// decoded by frame(i), so opening a sequence is cheap and frame(i) may be called from several
// threads at once.
//
// Invariants of frame(i): utime = the RGB time stamp, depth_utime = the associated depth
// time stamp (|difference| <= max_time_difference_us), seq = the RGB image's index in
// rgb.txt (0-based, counting every listed image, so unmatched ones leave gaps), camera = the
// sequence's intrinsics, T_body_camera = identity (for a TUM folder the body frame is the
// camera's optical frame: the player publishes the IMU and the ground truth in it), and
// RgbdFrame's own invariants (rgb R,G,B; depth in millimetres).
//
// The camera: a `camera.txt` in the folder (tum_lists.h: intrinsics, image size, lens, sensor
// profile; kestrel-sim writes one) wins over the folder's name (tum_camera.h);
// SequenceOptions::intrinsics wins over both. Its mounting line is checked but not applied
// (above).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "common/camera.h"
#include "common/rgbd_frame.h"
#include "common/trajectory.h"
#include "drivers/tum/tum_camera.h"
#include "drivers/tum/tum_images.h"
#include "drivers/tum/tum_lists.h"

namespace kestrel::tum {

struct SequenceOptions {
  /// Largest |t_rgb - t_depth| of an associated pair, microseconds (TUM uses 20 ms).
  int64_t max_time_difference_us = 20000;
  /// Multiplies every depth reading (TUM suggests about 1.035 for freiburg1); finite, > 0.
  double depth_scale_correction = 1.0;
  /// Replaces the intrinsics chosen from camera.txt or the folder name (width and height stay
  /// theirs).
  std::optional<PinholeCamera> intrinsics;
};

/// How the RGB and depth lists were associated.
struct AssociationStats {
  size_t rgb_images = 0;    ///< lines in rgb.txt
  size_t depth_images = 0;  ///< lines in depth.txt
  size_t frames = 0;        ///< associated pairs
  size_t unmatched_rgb = 0;  ///< no depth image within the tolerance: not a frame
  size_t unused_depth = 0;   ///< nearest to no RGB image
  size_t shared_depth = 0;   ///< serving two (or more) RGB images
};

class TumSequence {
 public:
  /// Reads `folder`; throws InputError (naming the file and line) for a missing folder or list,
  /// a malformed or out-of-order line, a non-finite value or a listed image that is missing,
  /// and (naming the folder and the tolerance) when no RGB image pairs with a depth image, so
  /// a sequence is never empty; std::invalid_argument for unusable options.
  explicit TumSequence(const std::string& folder, SequenceOptions options = {});

  size_t size() const { return frames_.size(); }
  bool empty() const { return frames_.empty(); }

  /// Decodes frame i (i < size()); throws InputError naming the list line and image for an
  /// undecodable image or one of the wrong size or type.
  RgbdFrame frame(size_t i) const;
  /// Time stamps of frame i without decoding it.
  int64_t utime(size_t i) const { return rgb_[frames_.at(i).rgb].utime; }
  int64_t depth_utime(size_t i) const { return depth_[frames_.at(i).depth].utime; }
  /// Index of frame i's RGB image in rgb.txt (its seq).
  size_t rgb_index(size_t i) const { return frames_.at(i).rgb; }

  const std::string& folder() const { return folder_; }
  TumCamera camera_model() const { return camera_model_; }
  const PinholeCamera& camera() const { return camera_; }
  /// The sensor model the frames name (RgbdFrame::sensor): camera.txt's, else the folder's.
  const std::string& sensor() const { return sensor_; }
  /// Whether the camera came from the folder's camera.txt rather than its name.
  bool has_camera_file() const { return has_camera_file_; }
  const AssociationStats& association() const { return stats_; }
  /// groundtruth.txt: T_world_camera (colour camera's optical frame in the mocap frame).
  const Trajectory& ground_truth() const { return ground_truth_; }
  bool has_ground_truth() const { return has_ground_truth_; }
  /// accelerometer.txt, on the Kinect accelerometer's axes (empty if the file is absent).
  const std::vector<AccelerometerSample>& accelerometer() const { return accelerometer_; }
  bool has_accelerometer() const { return has_accelerometer_; }

 private:
  struct FrameRef {
    size_t rgb;
    size_t depth;
  };
  std::string path_of(const ImageEntry& e) const;
  void check_images_exist(const std::vector<ImageEntry>& list, const std::string& list_path) const;

  std::string folder_;
  std::string rgb_list_;
  std::string depth_list_;
  TumCamera camera_model_ = TumCamera::kUnknown;
  PinholeCamera camera_;
  std::string sensor_;
  bool has_camera_file_ = false;
  DepthToMillimetres to_mm_;
  std::vector<ImageEntry> rgb_;
  std::vector<ImageEntry> depth_;
  std::vector<FrameRef> frames_;
  AssociationStats stats_;
  Trajectory ground_truth_;
  bool has_ground_truth_ = false;
  std::vector<AccelerometerSample> accelerometer_;
  bool has_accelerometer_ = false;
};

}  // namespace kestrel::tum
