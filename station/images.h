#pragma once
// Camera previews for the page: CAMERA_RGBD frames thinned in sensor time and compressed
// with the RGB-D codec's JPEG encoder (common/transport/rgbd_codec.h) — the colour image as it
// is, the depth image as a false-colour picture (near red, far blue, no reading black).
//
// Invariants: at most one preview per `period_s` of the frames' utime (a utime that goes
// backwards, a replay restarted, starts the count again); a frame is decoded only when a
// preview is due, so skipped frames cost nothing; a frame the codec refuses throws InputError
// naming the channel and leaves the thinning as it was.

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "kestrel/rgbd_frame_t.hpp"

namespace kestrel::station {

struct PreviewOptions {
  double period_s = 0.5;     ///< at most one preview per this much sensor time
  int jpeg_quality = 70;     ///< 1..100
  double depth_far_m = 5.0;  ///< depth at and beyond this gets the farthest colour
};

struct Preview {
  int64_t utime = 0;
  std::vector<uint8_t> colour_jpeg;  ///< empty when the frame has no colour image
  std::vector<uint8_t> depth_jpeg;   ///< empty when the frame has no depth image
};

/// The false-colour picture of a depth image (CV_16UC1 mm) as CV_8UC3 R,G,B.
cv::Mat depth_picture(const cv::Mat& depth_mm, double far_m);

class PreviewThinner {
 public:
  /// Throws std::invalid_argument for a non-positive period or a quality outside 1..100.
  explicit PreviewThinner(const PreviewOptions& options);
  std::optional<Preview> on_frame(const kestrel::rgbd_frame_t& m, const char* channel);
  void reset() { last_utime_.reset(); }

 private:
  PreviewOptions options_;
  std::optional<int64_t> last_utime_;
};

}  // namespace kestrel::station
