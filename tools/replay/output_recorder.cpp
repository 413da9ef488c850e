#include "tools/replay/output_recorder.h"

#include <algorithm>
#include <climits>
#include <deque>
#include <tuple>

namespace kestrel::replay {

std::map<std::string, int> channel_depths(const std::string& input_channel,
                                          const ProcessTable& table) {
  const ConsumerMap consumers = table.consumers();
  std::map<std::string, int> depth{{input_channel, 0}};
  std::deque<std::string> queue{input_channel};
  while (!queue.empty()) {
    const std::string channel = queue.front();
    queue.pop_front();
    const auto it = consumers.find(channel);
    if (it == consumers.end()) continue;
    for (const auto& process : it->second) {
      for (const auto& out : table.processes().at(process).publications) {
        if (depth.emplace(out, depth[channel] + 1).second) queue.push_back(out);
      }
    }
  }
  return depth;
}

OutputRecorder::OutputRecorder(const std::string& path) : writer_(path) {}

void OutputRecorder::add(const std::string& channel, const uint8_t* data, size_t size) {
  pending_.push_back({channel, std::vector<uint8_t>(data, data + size)});
}

void OutputRecorder::flush_event(int64_t timestamp, const std::map<std::string, int>& depths) {
  auto depth_of = [&](const std::string& channel) {
    const auto it = depths.find(channel);
    return it == depths.end() ? INT_MAX : it->second;
  };
  // stable_sort keeps the arrival order within a channel.
  std::stable_sort(pending_.begin(), pending_.end(), [&](const Output& a, const Output& b) {
    return std::forward_as_tuple(depth_of(a.channel), a.channel) <
           std::forward_as_tuple(depth_of(b.channel), b.channel);
  });
  for (const auto& out : pending_) {
    writer_.write(out.channel, timestamp, out.data);
    ++recorded_[out.channel];
  }
  pending_.clear();
}

void OutputRecorder::close() { writer_.close(); }

int64_t OutputRecorder::total() const {
  int64_t n = 0;
  for (const auto& [channel, count] : recorded_) n += count;
  return n;
}

}  // namespace kestrel::replay
