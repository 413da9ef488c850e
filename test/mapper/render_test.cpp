// The renders show what the map holds: colours of known cells in the top view and the slice,
// something drawn in the perspective view, and a small image for an empty map.
#include <gtest/gtest.h>

#include <algorithm>

#include <opencv2/core.hpp>

#include "mapper/render.h"

namespace kestrel::mapper {
namespace {

// A 2 m x 1 m floor of free cells at z in [0, 0.1); a 3-cell tall post of occupied cells at
// x, y in [0.5, 0.6); one occupied cell on the floor layer at x, y in [1.5, 1.6) x [0, 0.1).
VoxelMap post_map() {
  VoxelMap map;
  Key k;
  for (double x = 0.05; x < 2.0; x += 0.1)
    for (double y = 0.05; y < 1.0; y += 0.1) {
      map.keys().key(x, y, 0.05, k);
      map.update(k, map.miss());
    }
  for (double z : {0.05, 0.15, 0.25}) {
    map.keys().key(0.55, 0.55, z, k);
    map.update(k, map.hit());
  }
  map.keys().key(1.55, 0.05, 0.05, k);
  map.update(k, map.hit());
  return map;
}

TEST(Render, TopViewColoursColumnsByTheirHighestOccupiedCell) {
  RenderOptions o;
  o.pixels_per_cell = 4;
  o.max_side_px = 80;  // no up-scaling of this small map: 4 px per cell
  const cv::Mat top = render_top_view(post_map(), o);
  ASSERT_EQ(top.cols, 20 * 4);
  ASSERT_EQ(top.rows, 10 * 4);
  // Image row 0 is the largest y. Post column: x cell 5, y cell 5 -> row (9 - 5) * 4.
  EXPECT_EQ(top.at<cv::Vec3b>(4 * 4 + 1, 5 * 4 + 1), height_colour(1.0));  // highest: red
  EXPECT_EQ(top.at<cv::Vec3b>(9 * 4 + 1, 15 * 4 + 1), height_colour(0.0)); // lowest: blue
  EXPECT_EQ(top.at<cv::Vec3b>(1, 1), cv::Vec3b(200, 200, 200));           // free only
  EXPECT_EQ(height_colour(1.0), cv::Vec3b(0, 0, 255));
  EXPECT_EQ(height_colour(0.0), cv::Vec3b(255, 0, 0));
}

TEST(Render, SliceShowsOneLayer) {
  RenderOptions o;
  o.pixels_per_cell = 2;
  o.max_side_px = 40;
  const VoxelMap map = post_map();
  const cv::Mat floor = render_slice(map, 0.05, o);
  EXPECT_EQ(floor.at<cv::Vec3b>(4 * 2, 5 * 2), cv::Vec3b(0, 0, 0));        // the post
  EXPECT_EQ(floor.at<cv::Vec3b>(0, 0), cv::Vec3b(255, 255, 255));          // free floor
  const cv::Mat above = render_slice(map, 0.25, o);
  EXPECT_EQ(above.at<cv::Vec3b>(4 * 2, 5 * 2), cv::Vec3b(0, 0, 0));        // the post's top
  EXPECT_EQ(above.at<cv::Vec3b>(0, 0), cv::Vec3b(128, 128, 128));          // unknown up there
}

TEST(Render, PerspectiveDrawsTheOccupiedCells) {
  RenderOptions o;
  const cv::Mat view = render_perspective(post_map(), o);
  ASSERT_EQ(view.cols, o.view_width_px);
  // Count saturated (height-coloured) pixels: the background and the caption are grey.
  int coloured = 0;
  for (int r = 0; r < view.rows; ++r)
    for (int c = 0; c < view.cols; ++c) {
      const cv::Vec3b& p = view.at<cv::Vec3b>(r, c);
      coloured += std::max({p[0], p[1], p[2]}) - std::min({p[0], p[1], p[2]}) > 80;
    }
  EXPECT_GT(coloured, 500);
  EXPECT_EQ(render_top_view(VoxelMap()).cols, 64);  // empty map: a small placeholder
}

}  // namespace
}  // namespace kestrel::mapper
