#pragma once
// Which cells one scan clears and which it marks occupied: the same answer as OctoMap's
// OccupancyOcTreeBase::computeUpdate (the core of OcTree::insertPointCloud) on the same rays,
// computed an order of magnitude faster.
//
// OctoMap walks every ray cell by cell. From one viewpoint the rays are far denser than the
// cells (at 128x96 and 10 cm, about a hundred ray steps land in each cleared cell), so most of
// that walking re-discovers cells already found. The cell search here turns it around: it
// grows the cleared region outwards from the camera's cell, face neighbour by face neighbour
// (every ray's cells form a face-connected path from there, so nothing is missed), and asks
// of each candidate cell whether some ray clears it. The rays that can reach a cell are found
// by projecting the cell into the depth image; usually the ray through the pixel nearest the
// cell's centre answers at once, by a slab test with error margins on that pixel's exact line
// (FootprintProjector::certainly_clears, a few tens of nanoseconds). Only cells it cannot
// settle (the region's rim, depth holes, grazing rays) go through the exact tests below.
//
// "Clears" is decided by interval arithmetic with explicit error bounds on OctoMap's own
// float/double computation (ray_cell_classifier.h): a ray that certainly clears or certainly misses
// the cell decides; a ray too close to a cell edge or corner for the bounds to decide is
// traced exactly with OctoMap's DDA (ray.h). So the result equals OctoMap's cell for cell, not
// approximately; the tests check it against OctoMap on real and synthetic scans.
//
// Method::kRayTrace is the plain per-ray walk (the reference, same result).
//
// Method::kDiscretized is a different map: OctoMap's endpoint-discretised insertion
// (insertPointCloud(..., discretize = true), i.e. OccupancyOcTreeBase::computeDiscreteUpdate).
// The scan's points are reduced to one per cell (the first point with each key), each replaced
// by its cell's centre (float(keyToCoord)), and those centres go through computeUpdate's rules
// (ray.h: a centre within max range is a hit, one beyond is cut at max range and only clears).
// A few hundred rays instead of thousands, so they are simply walked with OctoMap's DDA. Same
// cells as computeDiscreteUpdate, with one deliberate exception: a point outside the tree's key
// range (about +-3.3 km at 10 cm) gives no ray here, where OctoMap's unchecked coordToKey wraps
// its key to the far side of the key range and clears max range towards that cell's centre.
// ScanOptions::discretize selects it for compute(scan, update).
//
// Not thread-safe (scratch space is reused between calls); use one integrator per thread.

#include <cstdint>
#include <optional>
#include <vector>

#include <Eigen/Core>

#include "mapper/cell_footprint.h"
#include "mapper/key_space.h"
#include "mapper/options.h"
#include "mapper/reach_pyramid.h"
#include "mapper/ray.h"
#include "mapper/ray_cell_classifier.h"
#include "mapper/scan.h"

namespace kestrel::mapper {

/// The outcome of one scan: every cell at most once, `free` and `occupied` disjoint (a cell
/// both cleared and hit is occupied, OctoMap's rule).
struct ScanUpdate {
  std::vector<Key> free;
  std::vector<Key> occupied;
  size_t rays = 0;          ///< valid points in the scan
  size_t cells_tested = 0;  ///< candidate cells examined by the cell search
  size_t cells_witnessed = 0;  ///< ... of them settled by the witness test alone
  size_t rays_traced = 0;   ///< rays walked cell by cell
  size_t ray_tests = 0;     ///< ray-cell tests made by the cell search
  void clear();
};

class ScanIntegrator {
 public:
  enum class Method { kCellSearch, kRayTrace, kDiscretized };

  ScanIntegrator(double resolution_m, const ScanOptions& options);
  ScanIntegrator(const ScanIntegrator&) = delete;
  ScanIntegrator& operator=(const ScanIntegrator&) = delete;

  /// Fills `update` for `scan`. Throws InputError if the camera centre lies outside the
  /// map's key range (about +-3.3 km at 10 cm).
  void compute(const Scan& scan, ScanUpdate& update, Method method);
  /// The same with the method the options choose: kDiscretized if options().discretize, else
  /// kCellSearch.
  void compute(const Scan& scan, ScanUpdate& update) {
    compute(scan, update, options_.discretize ? Method::kDiscretized : Method::kCellSearch);
  }

  const KeySpace& keys() const { return keys_; }
  const ScanOptions& options() const { return options_; }

 private:
  struct Pending {  // a cleared cell whose neighbours are still to be looked at
    int idx;
    Key key;
  };
  struct RayCache {
    Ray ray;
    RayBounds bounds;
  };
  enum : uint8_t { kTested = 1, kCleared = 2, kOccupied = 4, kEndpoint = 8 };

  void begin_grid(const Scan& scan);
  void begin(const Scan& scan);
  void begin_pixels(const Scan& scan);
  void begin_axis_parts(const Scan& scan);
  void mark(int idx, const Key& key, uint8_t flags);
  int index(const Key& key) const;
  RayCache& ray(size_t sample);
  bool traced(size_t sample) const { return ray_state_[sample] == built_ + 1; }
  void trace_sample(size_t sample);
  void set_cleared(int idx, const Key& key);
  bool witness_clears(const Key& cell, int idx, const Eigen::Vector3d& centre, float min_reach,
                      bool& tried);
  bool some_ray_may_reach(const Key& cell, float& min_reach, Eigen::Vector3d& centre) const;
  bool cleared_by_some_ray(const Key& cell, const Eigen::Vector3d& centre, int idx, bool witnesses_tried);
  bool clip_rows(const CellFootprint& f);
  bool try_ray(size_t sample, const Key& cell, int idx);
  void grow_from_origin();
  void test_cell(int idx, const Key& cell);
  void collect(ScanUpdate& update);
  void compute_discretized();
  void trace_cell_centre(const Key& key);
  void touch(int idx, uint8_t flags);
  void walk_rays();
  void collect_discretized(ScanUpdate& update);

  KeySpace keys_;
  ScanOptions options_;

  // Per scan.
  const Scan* scan_ = nullptr;
  Key key_origin_;
  int base_[3] = {0, 0, 0};      // key of grid cell (0, 0, 0)
  double hit_range2_ = 0.0;      // a point is a hit iff its squared range is <= this
  int side_ = 0;                 // the scratch grid is side_^3 cells around the origin
  FootprintProjector projector_;
  std::optional<RayCellClassifier> classifier_;
  // Pixel s's ray is built for this scan (at rays_[ray_slot_[s]]) if ray_state_[s] >= built_,
  // and has been walked if it is built_ + 1 (kept apart from the rays: the cell search checks
  // it for many pixels).
  uint32_t built_ = 0;
  size_t cells_tested_ = 0;
  size_t cells_witnessed_ = 0;
  size_t rays_traced_ = 0;
  size_t ray_tests_ = 0;
  int stride_[3] = {1, 0, 0};    // grid index step per key step along each axis

  // Scratch, reused.
  std::vector<uint8_t> cells_;             // flags per grid cell
  std::vector<std::pair<int, Key>> touched_;
  std::vector<Pending> queue_;
  size_t pixels_ = 0;                      // cols * rows of the scan
  float* reach_ = nullptr;                 // upper bound of each ray's length (0: no ray);
                                           // level 0 of reach_max_
  std::vector<float> s_end_lo_;            // lower bound of its end's camera depth (0: clears nothing)
  ReachPyramid reach_max_;                 // max of reach_ over any pixel rectangle
  // Per axis and grid coordinate (key - base_): the camera-frame part of the cell centre, and
  // the squared gap to / exit along that axis from the origin (for a cheap min_reach bound).
  struct AxisPart {
    double camera[3];
    double gap2;
    double exit_minus_gap2;
  };
  std::vector<AxisPart> axis_part_[3];
  Eigen::Vector3d box_half_;               // camera-frame half extents of a grown cell
  double quick_margin_ = 0.0;
  std::vector<int> end_cell_;              // grid index of each hit's cell (-1: none)
  std::vector<RayCache> rays_;
  std::vector<int> row_lo_, row_hi_;       // clip_rows(): pixel range per row
  std::vector<uint32_t> ray_state_;
  std::vector<uint32_t> ray_slot_;         // where in rays_ a built ray is
  std::vector<uint64_t> far_endpoints_;    // kDiscretized: packed endpoint keys outside the grid
  // kDiscretized: grid indices of the cells whose flags were set (touched_ without keys: the
  // key follows from the index), the first touched_count_ entries.
  std::vector<int> touched_idx_;
  size_t touched_count_ = 0;
  std::vector<Key> endpoints_;             // kDiscretized: the distinct endpoint cells in the grid
  std::vector<IndexWalk> walks_;           // kDiscretized: the rays to walk, at their first cell
  // kDiscretized: per axis, first_float() of every grid coordinate 0..side_ (for base
  // float_base_[a]), so that a point is placed in its cell by float comparisons.
  std::vector<float> first_float_[3];
  int float_base_[3] = {-1, -1, -1};
};

}  // namespace kestrel::mapper
