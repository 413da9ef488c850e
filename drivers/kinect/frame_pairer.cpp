#include "drivers/kinect/frame_pairer.h"

#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace kestrel::kinect {
namespace {

// More unused depth frames than this cannot all be candidates for the next RGB frame at
// 30 Hz; the bound keeps memory flat if the RGB stream stops.
constexpr size_t kMaxWaitingDepth = 8;

}  // namespace

int64_t DeviceClock::to_microseconds(uint32_t ticks) {
  if (!started_) {
    started_ = true;
    last_ticks_ = ticks;
    last_unwrapped_ = ticks;
  } else {
    // The difference modulo 2^32, read as signed: forward or a little back, across a wrap.
    last_unwrapped_ += static_cast<int32_t>(ticks - last_ticks_);
    last_ticks_ = ticks;
  }
  return last_unwrapped_ / kTicksPerMicrosecond;
}

FramePairer::FramePairer(PairerOptions options) : options_(options) {
  if (options_.max_difference_us < 0 || options_.wait_us < 0 || options_.frame_period_us <= 0)
    throw std::invalid_argument("frame pairer: negative time or non-positive frame period");
}

void FramePairer::count_gap(int64_t gap_us, int64_t& dropped) const {
  const double periods = static_cast<double>(gap_us) / static_cast<double>(options_.frame_period_us);
  if (periods > 1.5) dropped += std::llround(periods) - 1;
}

void FramePairer::add_rgb(StreamFrame frame) {
  if (last_rgb_us_ && frame.device_us <= *last_rgb_us_) {
    ++stats_.out_of_order;
    return;
  }
  if (last_rgb_us_) count_gap(frame.device_us - *last_rgb_us_, stats_.dropped_rgb);
  last_rgb_us_ = frame.device_us;
  ++stats_.rgb_frames;
  if (waiting_rgb_) decide();  // its depth never came: the next RGB frame is here
  waiting_rgb_ = std::move(frame);
  if (!depths_.empty() && depths_.back().device_us >= waiting_rgb_->device_us) decide();
}

void FramePairer::add_depth(StreamFrame frame) {
  if (last_depth_us_ && frame.device_us <= *last_depth_us_) {
    ++stats_.out_of_order;
    return;
  }
  if (last_depth_us_) count_gap(frame.device_us - *last_depth_us_, stats_.dropped_depth);
  last_depth_us_ = frame.device_us;
  ++stats_.depth_frames;
  depths_.push_back(std::move(frame));
  if (depths_.size() > kMaxWaitingDepth) drop_oldest_depth();
  if (waiting_rgb_ && depths_.back().device_us >= waiting_rgb_->device_us) decide();
}

void FramePairer::poll(int64_t host_utime) {
  if (waiting_rgb_ && host_utime - waiting_rgb_->host_utime >= options_.wait_us) decide();
}

void FramePairer::flush() {
  if (waiting_rgb_) decide();
  while (!depths_.empty()) drop_oldest_depth();
}

void FramePairer::drop_oldest_depth() {
  if (served_us_ && depths_.front().device_us == *served_us_)
    served_us_.reset();
  else
    ++stats_.unused_depth;
  depths_.pop_front();
}

void FramePairer::decide() {
  const int64_t t_rgb = waiting_rgb_->device_us;
  size_t best = depths_.size();
  int64_t best_difference = options_.max_difference_us;
  for (size_t i = 0; i < depths_.size(); ++i) {
    const int64_t difference = std::llabs(depths_[i].device_us - t_rgb);
    if (difference <= best_difference && (best == depths_.size() || difference < best_difference)) {
      best = i;
      best_difference = difference;
    }
  }
  if (best < depths_.size()) {
    // Depth frames before the chosen one are older still: no later RGB frame can use them.
    for (size_t i = 0; i < best; ++i) drop_oldest_depth();
    // The chosen one stays for the next RGB frame, which gets its own copy of the image.
    StreamFrame depth = depths_.front();
    depth.image = depth.image.clone();
    if (served_us_ && *served_us_ == depth.device_us) ++stats_.shared_depth;
    served_us_ = depth.device_us;
    ready_.push_back({std::move(*waiting_rgb_), std::move(depth)});
    ++stats_.paired;
  } else {
    ++stats_.unpaired_rgb;
    while (!depths_.empty() && depths_.front().device_us < t_rgb - options_.max_difference_us) drop_oldest_depth();
  }
  waiting_rgb_.reset();
}

std::optional<PairedFrame> FramePairer::next() {
  if (ready_.empty()) return std::nullopt;
  PairedFrame p = std::move(ready_.front());
  ready_.pop_front();
  return p;
}

}  // namespace kestrel::kinect
