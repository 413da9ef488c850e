#include "tools/monitor/message_types.h"

#include <stdexcept>

#include "common/transport/channels.h"
#include "common/transport/message.h"
#include "kestrel/camera_info_t.hpp"
#include "kestrel/ground_truth_t.hpp"
#include "kestrel/imu_t.hpp"
#include "kestrel/octomap_t.hpp"
#include "kestrel/plan_covariance_t.hpp"
#include "kestrel/plan_request_t.hpp"
#include "kestrel/plan_t.hpp"
#include "kestrel/pose3_t.hpp"
#include "kestrel/pose_t.hpp"
#include "kestrel/process_status_t.hpp"
#include "kestrel/rejection_counts_t.hpp"
#include "kestrel/rejection_reason_t.hpp"
#include "kestrel/replay_ack_t.hpp"
#include "kestrel/map_save_request_t.hpp"
#include "kestrel/playback_command_t.hpp"
#include "kestrel/playback_status_t.hpp"
#include "kestrel/replay_control_t.hpp"
#include "kestrel/rgbd_frame_t.hpp"
#include "kestrel/slam_correction_t.hpp"
#include "kestrel/slam_edge_t.hpp"
#include "kestrel/slam_graph_t.hpp"
#include "kestrel/slam_keyframe_t.hpp"
#include "kestrel/state_t.hpp"
#include "kestrel/vehicle_command_t.hpp"
#include "kestrel/vo_update_t.hpp"

namespace kestrel::monitor {
namespace {

template <class Msg>
MessageType type_of() {
  return {Msg::getTypeName(), Msg::getHash(),
          [](const void* data, size_t size, const std::string& channel) {
            transport::decode_message<Msg>(data, size, channel);
          }};
}

int64_t read_fingerprint(const uint8_t* p) {
  uint64_t v = 0;
  for (int i = 0; i < 8; ++i) v = (v << 8) | p[i];
  return static_cast<int64_t>(v);
}

}  // namespace

const std::vector<MessageType>& kestrel_types() {
  // One line per file in lcmtypes/.
  static const std::vector<MessageType> types = {
      type_of<kestrel::camera_info_t>(),     type_of<kestrel::ground_truth_t>(),
      type_of<kestrel::imu_t>(),             type_of<kestrel::octomap_t>(),
      type_of<kestrel::plan_request_t>(),    type_of<kestrel::plan_t>(),
      type_of<kestrel::plan_covariance_t>(), type_of<kestrel::pose3_t>(),
      type_of<kestrel::pose_t>(),
      type_of<kestrel::process_status_t>(),  type_of<kestrel::rejection_counts_t>(),
      type_of<kestrel::rejection_reason_t>(), type_of<kestrel::replay_ack_t>(),
      type_of<kestrel::replay_control_t>(),  type_of<kestrel::rgbd_frame_t>(),
      type_of<kestrel::slam_correction_t>(), type_of<kestrel::slam_edge_t>(),
      type_of<kestrel::slam_graph_t>(),      type_of<kestrel::slam_keyframe_t>(),
      type_of<kestrel::state_t>(),           type_of<kestrel::vehicle_command_t>(),
      type_of<kestrel::vo_update_t>(),       type_of<kestrel::map_save_request_t>(),
      type_of<kestrel::playback_command_t>(), type_of<kestrel::playback_status_t>(),
  };
  return types;
}

const MessageType* find_type(const std::string& name) {
  const std::string package = "kestrel.";
  const std::string bare = name.rfind(package, 0) == 0 ? name.substr(package.size()) : name;
  for (const auto& t : kestrel_types())
    if (t.name == bare) return &t;
  return nullptr;
}

const MessageType* identify(const void* data, size_t size) {
  if (size < 8) return nullptr;
  const int64_t fingerprint = read_fingerprint(static_cast<const uint8_t*>(data));
  for (const auto& t : kestrel_types())
    if (t.fingerprint == fingerprint) return &t;
  return nullptr;
}

std::map<std::string, const MessageType*> default_channel_types() {
  namespace ch = kestrel::channel;
  const std::vector<std::pair<const char*, const char*>> table = {
      {ch::kCameraRgbd, "rgbd_frame_t"},          {ch::kImu, "imu_t"},
      {ch::kGroundTruth, "ground_truth_t"},       {ch::kVoUpdate, "vo_update_t"},
      {ch::kState, "state_t"},                    {ch::kSlamCorrection, "slam_correction_t"},
      {ch::kSlamGraph, "slam_graph_t"},           {ch::kMapOctomap, "octomap_t"},
      {ch::kSlamGraphUnplaced, "slam_graph_t"},
      {ch::kPlanRequest, "plan_request_t"},       {ch::kPlan, "plan_t"},
      {ch::kPlanCovariance, "plan_covariance_t"},
      {ch::kVehicleCommand, "vehicle_command_t"}, {ch::kProcessStatus, "process_status_t"},
      {ch::kReplayControl, "replay_control_t"},   {ch::kReplayAck, "replay_ack_t"},
      {ch::kProcessRejections, "rejection_counts_t"},
      {ch::kSlamSaveMap, "map_save_request_t"},   {ch::kPlaybackCommand, "playback_command_t"},
      {ch::kPlaybackStatus, "playback_status_t"},
  };
  std::map<std::string, const MessageType*> map;
  for (const auto& [channel, type] : table) map[channel] = find_type(type);
  return map;
}

std::pair<std::string, const MessageType*> parse_channel_type(const std::string& spec) {
  const size_t eq = spec.find('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == spec.size())
    throw std::invalid_argument("'" + spec + "' is not CHANNEL=TYPE");
  const std::string type = spec.substr(eq + 1);
  const MessageType* t = find_type(type);
  if (!t) throw std::invalid_argument("unknown message type '" + type + "'");
  return {spec.substr(0, eq), t};
}

}  // namespace kestrel::monitor
