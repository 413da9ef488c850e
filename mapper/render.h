#pragma once
// Pictures of the map for the operator, drawn with OpenCV only, so a map can be looked at
// without octovis or any other viewer.
//
//  * top view: every column of cells seen from above, the highest occupied cell coloured by
//    its height (blue low, red high), columns with free cells only in light grey, never-seen
//    columns in dark grey; a 1 m scale bar and the height range are written on it;
//  * horizontal slice: one layer of cells at a height, occupied black, free white, unknown grey;
//  * perspective view: the occupied cells as shaded cubes (painter's order) from above and to
//    the side of the map's centre, coloured by height.
//
// All images are BGR (CV_8UC3), ready for image::write_png (common/image/image_io.h). An empty map gives a small grey image.
// World x points right and world y up in the top view and the slice.

#include <opencv2/core/mat.hpp>

#include "mapper/voxel_map.h"

namespace kestrel::mapper {

struct RenderOptions {
  int pixels_per_cell = 6;         ///< top view and slice: pixels per cell side (at least;
                                   ///< more for small maps, to about 600 px)
  int max_side_px = 2400;          ///< ... reduced so that no side exceeds this
  int view_width_px = 1024;        ///< perspective view size
  int view_height_px = 768;
  double view_azimuth_deg = -60.0; ///< perspective: camera direction around the map's centre
  double view_elevation_deg = 35.0;
};

cv::Mat render_top_view(const VoxelMap& map, const RenderOptions& options = {});
/// The layer of cells containing height z_m.
cv::Mat render_slice(const VoxelMap& map, double z_m, const RenderOptions& options = {});
cv::Mat render_perspective(const VoxelMap& map, const RenderOptions& options = {});

/// BGR colour for a value t in [0, 1] (blue, cyan, green, yellow, red).
cv::Vec3b height_colour(double t);

}  // namespace kestrel::mapper
