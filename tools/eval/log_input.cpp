#include "tools/eval/log_input.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <map>
#include <optional>
#include <set>

#include "common/error.h"
#include "common/time.h"
#include "common/transport/channels.h"
#include "common/transport/convert.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/slam_graph_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vo_update_t.hpp"
#include "tools/eval/vo_chain.h"

namespace kestrel::eval {
namespace {

// The first four bytes of every LCM log event (lcm-logger's format).
constexpr uint8_t kLogSync[4] = {0xED, 0xA1, 0xDA, 0x01};

enum class Kind { kUnknown, kGroundTruth, kState, kVo, kSlamGraph };

const char* type_name(Kind kind) {
  switch (kind) {
    case Kind::kGroundTruth:
      return kestrel::ground_truth_t::getTypeName();
    case Kind::kState:
      return kestrel::state_t::getTypeName();
    case Kind::kVo:
      return kestrel::vo_update_t::getTypeName();
    case Kind::kSlamGraph:
      return kestrel::slam_graph_t::getTypeName();
    case Kind::kUnknown:
      break;
  }
  return "unknown";
}

Kind kind_of_channel(const std::string& channel) {
  if (channel == channel::kGroundTruth) return Kind::kGroundTruth;
  if (channel == channel::kState) return Kind::kState;
  if (channel == channel::kVoUpdate) return Kind::kVo;
  if (channel == channel::kSlamGraph) return Kind::kSlamGraph;
  return Kind::kUnknown;
}

// The message type from its LCM fingerprint (the first 8 bytes, big-endian).
Kind kind_of_message(const std::vector<uint8_t>& data) {
  if (data.size() < 8) return Kind::kUnknown;
  uint64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | data[static_cast<size_t>(i)];
  const auto h = static_cast<int64_t>(hash);
  if (h == kestrel::ground_truth_t::getHash()) return Kind::kGroundTruth;
  if (h == kestrel::state_t::getHash()) return Kind::kState;
  if (h == kestrel::vo_update_t::getHash()) return Kind::kVo;
  if (h == kestrel::slam_graph_t::getHash()) return Kind::kSlamGraph;
  return Kind::kUnknown;
}

struct Scan {
  std::map<std::string, size_t> counts;                           // events per channel
  std::map<std::string, std::vector<std::vector<uint8_t>>> data;  // kept channels only
  std::string damage;
};

Scan scan_log(const std::string& path, const std::vector<std::string>& keep) {
  transport::LogReader reader(path);
  Scan scan;
  while (auto event = reader.next()) {
    ++scan.counts[event->channel];
    if (std::find(keep.begin(), keep.end(), event->channel) != keep.end())
      scan.data[event->channel].push_back(std::move(event->data));
  }
  scan.damage = reader.damage_report();
  return scan;
}

std::string list_channels(const Scan& scan) {
  if (scan.counts.empty()) return "the log has no events";
  std::string s = "channels in the log:";
  for (const auto& [name, n] : scan.counts) s += " " + name + " (" + std::to_string(n) + ")";
  return s;
}

// Builds the trajectory of one channel, message by message.
class ChannelReader {
 public:
  ChannelReader(const std::string& channel, TrajectoryInput& out)
      : channel_(channel), out_(out), kind_(kind_of_channel(channel)) {}

  void add(const std::vector<uint8_t>& data) {
    ++out_.diagnostics.messages;
    const Kind kind = kind_of_message(data);
    if (kind_ == Kind::kUnknown && kind != Kind::kUnknown) kind_ = kind;
    if (kind != kind_ || kind == Kind::kUnknown) {
      ++out_.diagnostics.wrong_type;
      return;
    }
    switch (kind_) {
      case Kind::kGroundTruth:
        if (const auto m = decode<kestrel::ground_truth_t>(data)) add_ground_truth(*m);
        break;
      case Kind::kState:
        if (const auto m = decode<kestrel::state_t>(data)) add_state(*m);
        break;
      case Kind::kVo:
        if (const auto m = decode<kestrel::vo_update_t>(data)) add_vo(*m);
        break;
      case Kind::kSlamGraph:
        if (auto m = decode<kestrel::slam_graph_t>(data)) add_graph(std::move(*m));
        break;
      case Kind::kUnknown:
        break;
    }
  }

  void finish() {
    if (kind_ == Kind::kVo) {
      out_.trajectory = chain_.trajectory();
      out_.frame_utimes = chain_.frame_utimes();
      out_.diagnostics.unknown_reference = chain_.unknown_reference();
      out_.diagnostics.no_pose = chain_.without_estimate();
      out_.frame = PoseFrame::kCamera;
    }
    if (kind_ == Kind::kSlamGraph && graph_) add_keyframes();
    out_.format = std::string("LCM log, ") + type_name(kind_);
  }

 private:
  // The message, or empty (counted) when its bytes are truncated or corrupt.
  template <class Msg>
  std::optional<Msg> decode(const std::vector<uint8_t>& data) {
    try {
      return transport::decode_message<Msg>(data.data(), data.size(), channel_);
    } catch (const InputError&) {
      ++out_.diagnostics.corrupt;
      return std::nullopt;
    }
  }

  // A pose from a message, or empty (counted) when it is not a valid rigid transform.
  std::optional<Eigen::Isometry3d> pose(const kestrel::pose3_t& m) {
    try {
      return transport::from_message(m, channel_.c_str());
    } catch (const InputError&) {
      ++out_.diagnostics.invalid_pose;
      return std::nullopt;
    }
  }

  // Messages must come in increasing utime; later repeats or steps back are counted.
  bool in_order(int64_t utime) {
    if (last_utime_ && utime <= *last_utime_) {
      ++out_.diagnostics.out_of_order;
      return false;
    }
    last_utime_ = utime;
    return true;
  }

  void add_ground_truth(const kestrel::ground_truth_t& m) {
    const PoseFrame frame =
        m.frame == kestrel::ground_truth_t::FRAME_BODY ? PoseFrame::kBody : PoseFrame::kCamera;
    if (m.frame != kestrel::ground_truth_t::FRAME_BODY &&
        m.frame != kestrel::ground_truth_t::FRAME_CAMERA) {
      ++out_.diagnostics.corrupt;
      return;
    }
    if (!out_.frame_utimes.empty() && frame != out_.frame) {
      throw InputError(channel_ + ": ground truth of the " + to_string(out_.frame) +
                       " changes to the " + to_string(frame) + " at " + format_seconds(m.utime));
    }
    if (!in_order(m.utime)) return;
    const auto T = pose(m.T_world_frame);
    if (!T) return;
    out_.frame = frame;
    out_.frame_utimes.push_back(m.utime);
    out_.trajectory.push_back(m.utime, *T);
  }

  void add_state(const kestrel::state_t& m) {
    if (!in_order(m.utime)) return;
    out_.frame = PoseFrame::kBody;
    out_.frame_utimes.push_back(m.utime);
    if (m.status != kestrel::state_t::STATUS_OK && m.status != kestrel::state_t::STATUS_DEGRADED) {
      ++out_.diagnostics.no_pose;
      return;
    }
    if (const auto T = pose(m.T_world_body)) out_.trajectory.push_back(m.utime, *T);
  }

  void add_vo(const kestrel::vo_update_t& m) {
    if (!in_order(m.utime)) return;
    VoStep step;
    step.utime = m.utime;
    step.reference_utime = m.reference_utime;
    step.no_reference = m.status == kestrel::vo_update_t::STATUS_NO_REFERENCE;
    if (m.status == kestrel::vo_update_t::STATUS_OK) {
      const auto T = pose(m.T_reference_current);
      step.valid = T.has_value();
      if (T) step.T_reference_current = *T;
    }
    chain_.add(step);
  }

  // Only the newest revision counts: every graph supersedes the ones before it, except that a
  // graph sharing no keyframe with the current one comes from a restarted SLAM (a new session,
  // slam/slam_messages.h), whose map starts afresh: the session before keeps its final graph.
  void add_graph(kestrel::slam_graph_t m) {
    if (graph_ && m.revision < graph_->revision) {
      ++out_.diagnostics.out_of_order;
      return;
    }
    if (graph_ && !graph_->keyframes.empty() && !m.keyframes.empty() && !shares_a_keyframe(*graph_, m))
      finished_sessions_.push_back(std::move(*graph_));
    graph_ = std::move(m);
  }

  static bool shares_a_keyframe(const kestrel::slam_graph_t& a, const kestrel::slam_graph_t& b) {
    std::set<int64_t> ids;
    for (const auto& k : a.keyframes) ids.insert(k.id);
    return std::any_of(b.keyframes.begin(), b.keyframes.end(), [&](const auto& k) { return ids.count(k.id) > 0; });
  }

  // The keyframes of each session's final graph, in time order: SLAM's optimised camera
  // trajectory.
  void add_keyframes() {
    std::vector<const kestrel::slam_keyframe_t*> keyframes;
    for (const auto& g : finished_sessions_)
      for (const auto& k : g.keyframes) keyframes.push_back(&k);
    for (const auto& k : graph_->keyframes) keyframes.push_back(&k);
    std::stable_sort(keyframes.begin(), keyframes.end(),
                     [](const auto* a, const auto* b) { return a->utime < b->utime; });
    out_.frame = PoseFrame::kCamera;
    for (const auto* k : keyframes) {
      if (!in_order(k->utime)) continue;
      out_.frame_utimes.push_back(k->utime);
      if (const auto T = pose(k->T_world_camera)) out_.trajectory.push_back(k->utime, *T);
    }
  }

  std::string channel_;
  TrajectoryInput& out_;
  Kind kind_;
  std::optional<kestrel::slam_graph_t> graph_;
  std::vector<kestrel::slam_graph_t> finished_sessions_;
  std::optional<int64_t> last_utime_;
  VoChain chain_;
};

// The camera mounting from the first VO message that carries a valid one.
std::optional<Eigen::Isometry3d> find_T_body_camera(
    const std::vector<std::vector<uint8_t>>& messages) {
  for (const auto& data : messages) {
    if (kind_of_message(data) != Kind::kVo) continue;
    try {
      const auto m = transport::decode_message<kestrel::vo_update_t>(data.data(), data.size(), "");
      return transport::from_message(m.T_body_camera, "");
    } catch (const InputError&) {
      // Corrupt, or no usable mounting in this one: the next message may have it.
    }
  }
  return std::nullopt;
}

}  // namespace

bool is_lcm_log(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open: " + std::strerror(errno));
  uint8_t head[4] = {0, 0, 0, 0};
  in.read(reinterpret_cast<char*>(head), 4);
  return in.gcount() == 4 && std::equal(head, head + 4, kLogSync);
}

TrajectoryInput read_log_input(const std::string& path, const std::vector<std::string>& channels) {
  std::vector<std::string> keep = channels;
  keep.push_back(channel::kVoUpdate);
  const Scan scan = scan_log(path, keep);

  const auto chosen = std::find_if(channels.begin(), channels.end(),
                                   [&](const std::string& c) { return scan.data.count(c) > 0; });
  if (chosen == channels.end()) {
    std::string wanted;
    for (const auto& c : channels) wanted += (wanted.empty() ? "" : " or ") + c;
    throw InputError(path + ": no messages on " + wanted + "; " + list_channels(scan));
  }

  TrajectoryInput out;
  out.source = path + ":" + *chosen;
  out.diagnostics.damage = scan.damage;
  ChannelReader reader(*chosen, out);
  for (const auto& data : scan.data.at(*chosen)) reader.add(data);
  reader.finish();
  if (const auto vo = scan.data.find(channel::kVoUpdate); vo != scan.data.end())
    out.T_body_camera = find_T_body_camera(vo->second);
  if (!out.T_body_camera && *chosen != channel::kVoUpdate)
    out.T_body_camera = find_T_body_camera(scan.data.at(*chosen));
  return out;
}

}  // namespace kestrel::eval
