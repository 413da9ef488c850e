#pragma once
// Subpixel refinement of a match: the translation d (and a brightness offset) that makes the
// current image around cur + d best match the reference patch around the reference feature,
// by ESM (the Jacobian averages both images' gradients), bilinear sampling.
//
// Invariant: on success the refined position is within max_shift of the start; on failure the
// start position is left unchanged.

#include <Eigen/Core>
#include <opencv2/core/mat.hpp>

namespace kestrel::vo {

struct SubpixelResult {
  Eigen::Vector2f position{0, 0};  ///< refined position in `cur`, pixels
  float rms_error = 0;             ///< grey levels over the patch
  int iterations = 0;
  bool ok = false;
};

/// Refines `cur_start` (pixels of `cur`) against the `window` x `window` patch of `ref` centred
/// on the integer pixel `ref_px`. Both patches, one pixel wider, must lie inside their images
/// (for the current one, after any shift up to `max_shift`).
SubpixelResult refine_subpixel(const cv::Mat& ref, const Eigen::Vector2i& ref_px, const cv::Mat& cur,
                               const Eigen::Vector2f& cur_start, int window, float max_shift,
                               int max_iterations = 6);

/// The same with the portable scalar sums only (refine_subpixel's SSE2 sums equal them bit for
/// bit; tests hold it to that).
SubpixelResult refine_subpixel_scalar(const cv::Mat& ref, const Eigen::Vector2i& ref_px, const cv::Mat& cur,
                                      const Eigen::Vector2f& cur_start, int window, float max_shift,
                                      int max_iterations = 6);

}  // namespace kestrel::vo
