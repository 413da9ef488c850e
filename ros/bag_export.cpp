#include "ros/bag_export.h"

#include <rosbag/bag.h>

#include "common/error.h"
#include "common/transport/channels.h"
#include "common/transport/log_file.h"
#include "common/transport/message.h"

namespace kestrel::ros1 {

BagExportStats export_log(const std::string& log_path, const BagExportOptions& options, rosbag::Bag& bag,
                          const std::function<bool()>& stopping) {
  BagExportStats stats;
  RosSinkOf sink([&bag](const std::string& topic, const ros::Time& t, const auto& m, bool /*latched*/) {
    bag.write(topic, t, m);
  });
  Exporter ex(options, sink, stats);
  transport::LogReader log(log_path);
  int64_t exported_channels = 0;
  while (auto e = log.next()) {
    if (stopping && stopping()) {
      stats.stopped = true;
      return stats;
    }
    ++stats.log_events;
    const std::string what = log_path + ": " + e->channel + " event " + std::to_string(e->event_number);
    if (e->channel == channel::kState) {
      ex.state(transport::decode_message<kestrel::state_t>(e->data.data(), e->data.size(), what), what);
      ++exported_channels;
    } else if (e->channel == channel::kVoUpdate) {
      ex.vo(transport::decode_message<kestrel::vo_update_t>(e->data.data(), e->data.size(), what), what);
      ++exported_channels;
    } else if (e->channel == channel::kGroundTruth) {
      ex.truth(transport::decode_message<kestrel::ground_truth_t>(e->data.data(), e->data.size(), what), what);
      ++exported_channels;
    } else if (e->channel == channel::kSlamGraph) {
      ex.graph(transport::decode_message<kestrel::slam_graph_t>(e->data.data(), e->data.size(), what), what);
      ++exported_channels;
    } else if (e->channel == channel::kPlan) {
      ex.plan(transport::decode_message<kestrel::plan_t>(e->data.data(), e->data.size(), what), what);
      ++exported_channels;
    } else if (e->channel == channel::kMapOctomap) {
      ex.map(transport::decode_message<kestrel::octomap_t>(e->data.data(), e->data.size(), what), what);
      ++exported_channels;
    } else if (e->channel == channel::kCameraRgbd) {
      ex.camera(transport::decode_message<kestrel::rgbd_frame_t>(e->data.data(), e->data.size(), what), what);
      if (options.images) ++exported_channels;
    }
  }
  if (!log.damage_report().empty()) throw InputError(log.damage_report() + " (no bag written)");
  if (exported_channels == 0)
    throw InputError(log_path + ": none of the channels exported (STATE, VO_UPDATE, GROUND_TRUTH, SLAM_GRAPH, PLAN, MAP_OCTOMAP" +
                     std::string(options.images ? ", CAMERA_RGBD" : "; CAMERA_RGBD only with --images") + ") is in the log (" +
                     std::to_string(stats.log_events) + " events)");
  // Channels present but nothing usable written (every VO_UPDATE without a pose, out of order):
  // a bag of the camera's mounting alone is not a result.
  int64_t written = stats.total();
  if (const auto it = stats.messages.find("/tf_static"); it != stats.messages.end()) written -= it->second;
  if (written == 0) {
    throw InputError(log_path + ": nothing exportable in the log's messages (" + std::to_string(stats.vo_without_estimate) +
                     " VO_UPDATEs without a pose, " + std::to_string(stats.vo_out_of_order) + " out of order)");
  }
  return stats;
}

}  // namespace kestrel::ros1
