#include "mapper/keyframe_store.h"

#include "common/numbers.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace kestrel::mapper {

void KeyframeOptions::validate() const {
  if (!(std::isfinite(max_megabytes) && max_megabytes > 0.0))
    throw std::invalid_argument("keyframe-megabytes: must be > 0");
  if (!(std::isfinite(bin_size_m) && bin_size_m > 0.0))
    throw std::invalid_argument("keyframe-bin-size: must be > 0");
  if (!(std::isfinite(bin_angle_deg) && bin_angle_deg > 0.0 && bin_angle_deg <= 180.0))
    throw std::invalid_argument("keyframe-bin-angle: must be in (0, 180]");
}

size_t StoredKeyframe::bytes() const {
  return sizeof(StoredKeyframe) + frame.depth_mm.total() * frame.depth_mm.elemSize() +
         frame.rgb.total() * frame.rgb.elemSize();
}

KeyframeStore::KeyframeStore(const KeyframeOptions& options) : options_(options) {
  options_.validate();
}

KeyframeStore::Bin KeyframeStore::bin_of(const Eigen::Isometry3d& T) const {
  const Eigen::Vector3d p = T.translation() / options_.bin_size_m;
  const Eigen::Vector3d axis = T.linear().col(2);
  const double sector = options_.bin_angle_deg * kPi / 180.0;
  const double azimuth = std::atan2(axis.y(), axis.x());
  const double elevation = std::asin(std::clamp(axis.z(), -1.0, 1.0));
  return {static_cast<int>(std::floor(p.x())), static_cast<int>(std::floor(p.y())),
          static_cast<int>(std::floor(p.z())), static_cast<int>(std::floor(azimuth / sector)),
          static_cast<int>(std::floor(elevation / sector))};
}

void KeyframeStore::unbin(int64_t id, const Bin& bin) {
  auto it = bins_.find(bin);
  if (it == bins_.end()) return;
  auto& ids = it->second;
  ids.erase(std::remove(ids.begin(), ids.end(), id), ids.end());
  if (ids.empty()) bins_.erase(it);
}

void KeyframeStore::add(StoredKeyframe keyframe) {
  const int64_t id = keyframe.id;
  if (auto old = keyframes_.find(id); old != keyframes_.end()) {
    bytes_ -= old->second.bytes();
    unbin(id, bin_of_id_.at(id));
    keyframes_.erase(old);
  }
  const Bin bin = bin_of(keyframe.T_world_camera);
  bytes_ += keyframe.bytes();
  keyframes_.emplace(id, std::move(keyframe));
  bin_of_id_[id] = bin;
  bins_[bin].push_back(id);
  const double budget = options_.max_megabytes * 1e6;
  while (static_cast<double>(bytes_) > budget && keyframes_.size() > 1) drop_one(id);
}

void KeyframeStore::drop_one(int64_t keep) {
  // The fullest bin; its oldest keyframe other than `keep`.
  const std::vector<int64_t>* fullest = nullptr;
  for (const auto& [bin, ids] : bins_) {
    const size_t candidates = ids.size() - (std::count(ids.begin(), ids.end(), keep) ? 1 : 0);
    if (candidates > 0 && (fullest == nullptr || ids.size() > fullest->size())) fullest = &ids;
  }
  if (fullest == nullptr) return;
  int64_t victim = fullest->front() == keep ? (*fullest)[1] : fullest->front();
  auto it = keyframes_.find(victim);
  bytes_ -= it->second.bytes();
  unbin(victim, bin_of_id_.at(victim));
  bin_of_id_.erase(victim);
  keyframes_.erase(it);
  ++dropped_;
}

bool KeyframeStore::set_pose(int64_t id, const Eigen::Isometry3d& T_world_camera) {
  auto it = keyframes_.find(id);
  if (it == keyframes_.end()) return false;
  it->second.T_world_camera = T_world_camera;
  const Bin bin = bin_of(T_world_camera);
  Bin& old = bin_of_id_.at(id);
  if (bin != old) {
    unbin(id, old);
    old = bin;
    bins_[bin].push_back(id);
  }
  return true;
}

const StoredKeyframe* KeyframeStore::find(int64_t id) const {
  auto it = keyframes_.find(id);
  return it == keyframes_.end() ? nullptr : &it->second;
}

std::vector<const StoredKeyframe*> KeyframeStore::in_time_order() const {
  std::vector<const StoredKeyframe*> out;
  out.reserve(keyframes_.size());
  for (const auto& [id, kf] : keyframes_) out.push_back(&kf);
  std::stable_sort(out.begin(), out.end(),
                   [](const StoredKeyframe* a, const StoredKeyframe* b) { return a->utime < b->utime; });
  return out;
}

void KeyframeStore::clear() {
  keyframes_.clear();
  bin_of_id_.clear();
  bins_.clear();
  bytes_ = 0;
}

}  // namespace kestrel::mapper
