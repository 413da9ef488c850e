#include "mapper/keyframe_store.h"

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

namespace {
// The options' own messages name the command-line options; ViewBins' would not.
const KeyframeOptions& validated(const KeyframeOptions& options) {
  options.validate();
  return options;
}
}  // namespace

KeyframeStore::KeyframeStore(const KeyframeOptions& options)
    : options_(validated(options)), bins_(options.bin_size_m, options.bin_angle_deg) {}

void KeyframeStore::add(StoredKeyframe keyframe) {
  const int64_t id = keyframe.id;
  if (auto old = keyframes_.find(id); old != keyframes_.end()) {
    bytes_ -= old->second.bytes();
    bins_.erase(id);  // a replaced keyframe is the newest of its bin
    keyframes_.erase(old);
  }
  bins_.insert(id, keyframe.T_world_camera);
  keyframe.stored_order = next_stored_order_++;
  bytes_ += keyframe.bytes();
  keyframes_.emplace(id, std::move(keyframe));
  const double budget = options_.max_megabytes * 1e6;
  while (static_cast<double>(bytes_) > budget && keyframes_.size() > 1) drop_one(id);
}

void KeyframeStore::drop_one(int64_t keep) {
  const std::optional<int64_t> victim = bins_.first_to_thin(keep);
  if (!victim) return;
  auto it = keyframes_.find(*victim);
  bytes_ -= it->second.bytes();
  bins_.erase(*victim);
  keyframes_.erase(it);
  ++dropped_;
}

bool KeyframeStore::set_pose(int64_t id, const Eigen::Isometry3d& T_world_camera) {
  auto it = keyframes_.find(id);
  if (it == keyframes_.end()) return false;
  it->second.T_world_camera = T_world_camera;
  bins_.insert(id, T_world_camera);
  return true;
}

const StoredKeyframe* KeyframeStore::find(int64_t id) const {
  auto it = keyframes_.find(id);
  return it == keyframes_.end() ? nullptr : &it->second;
}

std::vector<const StoredKeyframe*> KeyframeStore::in_stored_order() const {
  std::vector<const StoredKeyframe*> out;
  out.reserve(keyframes_.size());
  for (const auto& [id, kf] : keyframes_) out.push_back(&kf);
  std::sort(out.begin(), out.end(), [](const StoredKeyframe* a, const StoredKeyframe* b) {
    return a->stored_order < b->stored_order;
  });
  return out;
}

void KeyframeStore::clear() {
  keyframes_.clear();
  bins_.clear();
  bytes_ = 0;
}

}  // namespace kestrel::mapper
