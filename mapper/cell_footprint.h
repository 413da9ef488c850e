#pragma once
// Which rays of a scan can pass through a given cell: the cell seen from the camera.
//
// A scan's rays leave the camera centre through the pixels of its grid. The rays that can
// pass through a cell are those whose pixel lies in the cell's image, so the cell search
// (scan_integrator.h) only looks at the pixels of that image, nearest the cell's centre first.
//
// Everything here is conservative: the cell is grown by a margin (1e-4 m) far larger than
// the distance between a ray as OctoMap walks it (float origin, float point) and the exact
// pixel direction used here (below 1e-6 m), so no ray that could touch the cell is left out.
// certainly_clears() is the same bound used the other way: the cell shrunk and the ray
// shortened by those errors, so a ray it accepts clears the cell in OctoMap's walk too.
//
// One projector serves every scan of an integrator: begin() redoes the pose-dependent parts
// and keeps the per-tile cones while the camera model stays the same.

#include <Eigen/Core>
#include <vector>

#include "mapper/key_space.h"
#include "mapper/scan.h"

namespace kestrel::mapper {

/// Pixels per side of the tiles the image is split into for coarse tests.
inline constexpr int kTilePixels = 4;

struct CellFootprint {
  double lo[3] = {0.0, 0.0, 0.0};  ///< the cell's bounds, world frame
  double hi[3] = {0.0, 0.0, 0.0};
  Eigen::Vector3d centre_in_camera;
  double radius2 = 0.0;  ///< squared radius of the sphere around the grown cell
  double centre_distance = 0.0;
  double cos_sphere = -1.0;  ///< cosine of the sphere's angular radius seen from the camera
  double sin_sphere = 1.0;
  float min_reach = 0.0f;  ///< a ray shorter than this cannot clear the cell
  /// Inclusive pixel rectangle holding the cell's image (empty when i0 > i1 or j0 > j1).
  int i0 = 0, i1 = -1, j0 = 0, j1 = -1;
  /// Pixel nearest the image of the cell's centre (clamped into the rectangle).
  int u_centre = 0, v_centre = 0;

  bool empty() const { return i0 > i1 || j0 > j1; }
};

class FootprintProjector {
 public:
  explicit FootprintProjector(const KeySpace& keys) : keys_(keys) {}
  void begin(const Scan& scan);

  /// The pixel nearest the image of the cell's centre, if the centre is in front of the camera
  /// and projects into the grid.
  bool centre_pixel(const Key& cell, int& u, int& v) const;
  CellFootprint footprint(const Key& cell) const;
  /// footprint() in two steps, so that a caller can drop the cell after the first: the cell's
  /// bounds, min_reach and pixel rectangle; then, if the rectangle is not empty, the rest (the
  /// sphere around the cell and the centre pixel) from the cell centre's camera-frame position.
  CellFootprint rectangle(const Key& cell) const;
  void complete(CellFootprint& f, const Eigen::Vector3d& centre_in_camera) const;

  /// True if OctoMap's walk of the ray through pixel (u, v) certainly clears the cell, given
  /// that the ray's end lies at camera depth >= s_end_lo along the pixel's direction: the
  /// pixel's line passes through the cell's interior, with room for every rounding error,
  /// after the start and leaves it before the end. False says nothing (the caller goes on to
  /// the exact tests). Never true for the origin's cell.
  bool certainly_clears(const Key& cell, int u, int v, double s_end_lo) const;

  /// Upper bound of the distance between OctoMap's float ray and the exact pixel line,
  /// apart from the 1e-6 relative error of the direction.
  double line_error() const { return line_error_; }
  /// How far the cell is grown on each side for the footprint (covers every rounding).
  double margin() const { return margin_; }

  /// False if no ray through the pixels of tile (ti, tj) can pass through the sphere around
  /// the cell (the tile's cone of directions and the sphere's cone do not overlap).
  bool tile_may_pass(const CellFootprint& f, int ti, int tj) const {
    const Tile& t = tiles_[static_cast<size_t>(tj) * tiles_x_ + ti];
    if (f.cos_sphere <= -1.0) return true;  // the camera is inside the sphere
    // The cones overlap if angle(centre, axis) <= tile half-angle + sphere half-angle (both
    // below 90 degrees, so comparing cosines is enough).
    const double cos_angle = f.centre_in_camera.dot(t.axis) / f.centre_distance;
    return cos_angle >= t.cos_half * f.cos_sphere - t.sin_half * f.sin_sphere - 1e-12;
  }

  /// False if the ray through pixel (u, v), of length at most `reach`, certainly does not
  /// clear the cell: its line misses the cell, or it ends before it could leave the cell.
  /// Cheap (a sphere test, then slab intervals along the pixel's exact direction with
  /// tolerances that cover the difference to OctoMap's float ray); rays that pass go on to the
  /// exact test.
  bool may_clear(const CellFootprint& f, int u, int v, float reach) const {
    const double a = ray_x_[static_cast<size_t>(u)], b = ray_y_[static_cast<size_t>(v)];
    const Eigen::Vector3d& c = f.centre_in_camera;
    const double cx = c.y() - c.z() * b, cy = c.z() * a - c.x(), cz = c.x() * b - c.y() * a;
    if (cx * cx + cy * cy + cz * cz > f.radius2 * (a * a + b * b + 1.0)) return false;
    return slabs_may_clear(f, u, v, reach);
  }

 private:
  bool slabs_may_clear(const CellFootprint& f, int u, int v, float reach) const;

  void make_tiles(const PinholeCamera& camera);

  const KeySpace& keys_;
  PinholeCamera camera_;                  // the scan's
  PinholeCamera tile_camera_;             // the camera the tiles were made for
  bool have_tiles_ = false;
  Eigen::Matrix<double, 3, 4> P_;         // world -> homogeneous pixel (u z, v z, z)
  Eigen::Matrix3d R_camera_world_;
  Eigen::Vector3d t_camera_world_;
  double origin_[3] = {0.0, 0.0, 0.0};
  double margin_ = 0.0;
  int cols_ = 0, rows_ = 0;
  std::vector<double> ray_x_, ray_y_;     // pixel ray direction (x/z, y/z) per column / row
  std::vector<Eigen::Vector3d> column_dir_, row_dir_;  // world-frame parts of the pixel rays
  double line_error_ = 0.0;               // distance of OctoMap's ray from the pixel's line
  double max_dir_norm_ = 1.0;             // largest |column_dir_ + row_dir_| over the pixels
  struct Tile {
    Eigen::Vector3d axis;  // unit direction of the tile's central ray, camera frame
    double cos_half, sin_half;  // half-angle of a cone holding every ray of the tile
  };
  int tiles_x_ = 0;
  std::vector<Tile> tiles_;
};

}  // namespace kestrel::mapper
