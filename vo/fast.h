#pragma once
// FAST-9 corner detection (Rosten & Drummond): a pixel is a corner when 9 contiguous pixels of
// the 16 on the radius-3 Bresenham circle around it are all brighter than centre + t or all
// darker than centre - t.
//
// Invariants, identical to OpenCV's cv::FAST(TYPE_9_16) so that one is the other's test:
//  * corners are looked for at 3 <= x < width - 3, 3 <= y < height - 3;
//  * score = (largest t' at which the pixel is still a corner) = min over the best arc of
//    |circle - centre| minus 1;
//  * with non-maximum suppression, a corner survives when its score is strictly greater than
//    the score of each of its 8 neighbours (0 for a neighbour that is not a corner);
//  * corners come out in raster order (row by row, left to right).
// The SSE2 path (x86-64 always, other CPUs when available) and the scalar path give the same
// corners; detect_fast9_scalar() exists so that tests can hold them to it.

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

namespace kestrel::vo {

struct FastCorner {
  int16_t x = 0;
  int16_t y = 0;
  int16_t score = 0;
};

/// Row buffers reused between calls so that detection allocates nothing once warm.
struct FastScratch {
  std::vector<uint8_t> scores;   // 3 rolling rows of scores
  std::vector<int16_t> columns;  // 3 rolling rows of corner columns
  std::vector<int> counts;
};

/// FAST-9 corners of an 8-bit grey image with intensity threshold `threshold` (1..254),
/// appended to `corners` (which is cleared first).
void detect_fast9(const cv::Mat& image, int threshold, bool nonmax_suppression,
                  std::vector<FastCorner>& corners, FastScratch& scratch);

/// The same with the portable scalar code only.
void detect_fast9_scalar(const cv::Mat& image, int threshold, bool nonmax_suppression,
                         std::vector<FastCorner>& corners, FastScratch& scratch);

/// The FAST score of the pixel at `p` (row stride `stride`), which need not be a corner:
/// max over the 16 arcs of 9 of min |circle - centre| (over pixels all on one side), minus 1.
int fast9_score(const uint8_t* p, int stride);

}  // namespace kestrel::vo
