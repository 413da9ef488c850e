#include "common/geometry/view_bins.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "common/numbers.h"

namespace kestrel {

ViewBins::ViewBins(double cell_m, double sector_deg) : cell_m_(cell_m), sector_rad_(sector_deg * kPi / 180.0) {
  if (!(std::isfinite(cell_m) && cell_m > 0.0)) throw std::invalid_argument("view bins: the cell must be > 0 m");
  if (!(std::isfinite(sector_deg) && sector_deg > 0.0 && sector_deg <= 180.0))
    throw std::invalid_argument("view bins: the sector must be in (0, 180] degrees");
}

ViewBins::Bin ViewBins::bin_of(const Eigen::Isometry3d& T) const {
  const Eigen::Vector3d p = T.translation() / cell_m_;
  const Eigen::Vector3d axis = T.linear().col(2);
  const double azimuth = std::atan2(axis.y(), axis.x());
  const double elevation = std::asin(std::clamp(axis.z(), -1.0, 1.0));
  // Sectors centred on the axes (a level camera looking along x is mid-sector, not on the
  // boundary where pitch jitter would split one place's views over two bins).
  return {static_cast<int>(std::floor(p.x())), static_cast<int>(std::floor(p.y())),
          static_cast<int>(std::floor(p.z())), static_cast<int>(std::floor(azimuth / sector_rad_ + 0.5)),
          static_cast<int>(std::floor(elevation / sector_rad_ + 0.5))};
}

void ViewBins::insert(int64_t id, const Eigen::Isometry3d& T_world_camera) {
  const Bin bin = bin_of(T_world_camera);
  if (auto it = bin_of_id_.find(id); it != bin_of_id_.end()) {
    if (it->second == bin) return;
    erase(id);
  }
  bin_of_id_[id] = bin;
  bins_[bin].push_back(id);
}

void ViewBins::erase(int64_t id) {
  const auto it = bin_of_id_.find(id);
  if (it == bin_of_id_.end()) return;
  const auto bin = bins_.find(it->second);
  auto& ids = bin->second;
  ids.erase(std::remove(ids.begin(), ids.end(), id), ids.end());
  if (ids.empty()) bins_.erase(bin);
  bin_of_id_.erase(it);
}

std::optional<int64_t> ViewBins::first_to_thin(std::optional<int64_t> keep) const {
  const std::vector<int64_t>* fullest = nullptr;
  for (const auto& [bin, ids] : bins_) {
    const bool only_keep = ids.size() == 1 && keep && ids.front() == *keep;
    // The fullest bin; among equally full ones, the one holding the oldest view (ids grow with
    // time), so that once every place is down to one view the oldest goes first.
    if (only_keep) continue;
    const bool older = fullest != nullptr && ids.size() == fullest->size() && ids.front() < fullest->front();
    if (fullest == nullptr || ids.size() > fullest->size() || older) fullest = &ids;
  }
  if (fullest == nullptr) return std::nullopt;
  return keep && fullest->front() == *keep ? (*fullest)[1] : fullest->front();
}

void ViewBins::clear() {
  bin_of_id_.clear();
  bins_.clear();
}

}  // namespace kestrel
