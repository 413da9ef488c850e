#pragma once
// Loading the images of a TUM RGB-D sequence into RgbdFrame's forms.
//
// * Colour: 8-bit, 3-channel PNG; returned in R,G,B channel order (OpenCV decodes B,G,R).
// * Depth: 16-bit, 1-channel PNG in TUM's units of 1/5000 m (0 = no reading); returned as
//   CV_16UC1 millimetres, rounded to nearest, after an optional scale correction (TUM notes
//   that freiburg1 depth may read about 3.5 % short). A reading that rounds to 0 mm (below
//   0.5 mm, which no Kinect produces) becomes "no reading"; one above 65.535 m saturates.
//
// Every failure throws InputError naming the list file and line that named the image, and
// the image: missing file, undecodable (corrupt) PNG, wrong size, wrong pixel type.

#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace kestrel::tum {

/// Where an image was listed, for error messages: "<list path>:<line>".
struct ListedAt {
  std::string list;
  int line = 0;
};

/// Loads a colour image of width x height; returns CV_8UC3 in R,G,B order.
cv::Mat load_rgb(const std::string& path, int width, int height, const ListedAt& listed_at);

/// Loads a depth image of width x height in TUM's raw units (CV_16UC1, 1/5000 m).
cv::Mat load_depth_raw(const std::string& path, int width, int height, const ListedAt& listed_at);

/// TUM's 1/5000 m units to millimetres, times a scale correction, through a lookup table.
class DepthToMillimetres {
 public:
  /// `scale_correction` must be finite and > 0 (throws std::invalid_argument otherwise).
  explicit DepthToMillimetres(double scale_correction = 1.0);
  cv::Mat operator()(const cv::Mat& depth_raw) const;
  uint16_t operator()(uint16_t raw) const { return table_[raw]; }

 private:
  std::vector<uint16_t> table_;
};

}  // namespace kestrel::tum
