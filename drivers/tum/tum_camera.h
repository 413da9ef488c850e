#pragma once
// The colour camera of a TUM RGB-D sequence, chosen from the folder name (or given by the
// folder's camera.txt, which wins: tum_sequence.h).
//
// TUM recorded with three Kinects, "freiburg1", "freiburg2" and "freiburg3"; the sequence
// folders carry that name (rgbd_dataset_freiburg1_xyz). For each, TUM publishes calibrated
// colour-camera intrinsics (https://vision.in.tum.de/data/datasets/rgbd-dataset/file_formats,
// "Intrinsic Camera Calibration of the Kinect"); for any other folder the ROS default
// 525/525/319.5/239.5 is used, as TUM advises for uncalibrated use. Images are 640x480.
//
// The images are not undistorted here (TUM's registered depth cannot be undistorted exactly):
// freiburg1 and freiburg2 report TUM's calibrated lens distortion with their raw images (fr1:
// 2-3 % radial over most of the image, 5-8 px; up to ~25 px in the corners), for consumers that
// map raw pixels to ideal ones (sensors::Lens); freiburg3's images are undistorted by TUM
// already, and unknown folders report none.

#include <optional>
#include <string>

#include "common/camera.h"
#include "common/rgbd_frame.h"
#include "drivers/tum/tum_lists.h"

namespace kestrel::tum {

enum class TumCamera { kFreiburg1, kFreiburg2, kFreiburg3, kUnknown };

/// The camera named in the last component of `folder` ("freiburg1" .. "freiburg3").
TumCamera detect_camera(const std::string& folder);

/// TUM's calibrated intrinsics for `camera` (ROS default for kUnknown), 640x480; distortion
/// (k1, k2, p1, p2, k3) for freiburg1 and freiburg2.
PinholeCamera camera_intrinsics(TumCamera camera);

/// "freiburg1", ..., "unknown (ROS default intrinsics)".
const char* camera_name(TumCamera camera);

/// The sensor model the frames name (RgbdFrame::sensor): kinect1 for freiburg1, whose Kinect
/// the profile was measured on; "" for the others (their timing is not measured here).
const char* sensor_model_of(TumCamera camera);

/// The folder's camera.txt (tum_lists.h), if it has one; InputError naming it if it is bad.
std::optional<CameraFile> camera_file_of(const std::string& folder);

/// The sensor model the frames name: `file`'s (a folder's camera.txt) if it names one, else
/// sensor_model_of(camera), the camera the folder's name says.
std::string sensor_model_of(TumCamera camera, const std::optional<CameraFile>& file);

/// The same for `folder`: sensor_model_of(detect_camera(folder), camera_file_of(folder)).
std::string sensor_model_of_folder(const std::string& folder);

}  // namespace kestrel::tum
