#pragma once
// Channel names (README "Channels" lists each with its type and producer).

namespace kestrel::channel {

inline constexpr const char* kCameraRgbd = "CAMERA_RGBD";       // rgbd_frame_t
inline constexpr const char* kImu = "IMU";                      // imu_t
inline constexpr const char* kGroundTruth = "GROUND_TRUTH";     // ground_truth_t
inline constexpr const char* kVoUpdate = "VO_UPDATE";           // vo_update_t
inline constexpr const char* kState = "STATE";                  // state_t
inline constexpr const char* kSlamCorrection = "SLAM_CORRECTION";  // slam_correction_t
inline constexpr const char* kSlamGraph = "SLAM_GRAPH";         // slam_graph_t
inline constexpr const char* kSlamGraphUnplaced = "SLAM_GRAPH_UNPLACED";  // slam_graph_t
inline constexpr const char* kSlamSaveMap = "SLAM_SAVE_MAP";    // map_save_request_t
inline constexpr const char* kMapOctomap = "MAP_OCTOMAP";       // octomap_t
inline constexpr const char* kPlanRequest = "PLAN_REQUEST";     // plan_request_t
inline constexpr const char* kPlan = "PLAN";                    // plan_t
inline constexpr const char* kPlanCovariance = "PLAN_COVARIANCE";  // plan_covariance_t
inline constexpr const char* kVehicleCommand = "VEHICLE_COMMAND"; // vehicle_command_t
inline constexpr const char* kProcessStatus = "PROCESS_STATUS"; // process_status_t
inline constexpr const char* kProcessRejections = "PROCESS_REJECTIONS"; // rejection_counts_t
inline constexpr const char* kReplayControl = "REPLAY_CONTROL"; // replay_control_t
inline constexpr const char* kReplayAck = "REPLAY_ACK";         // replay_ack_t
inline constexpr const char* kPlaybackCommand = "PLAYBACK_COMMAND"; // playback_command_t
inline constexpr const char* kPlaybackStatus = "PLAYBACK_STATUS";   // playback_status_t

}  // namespace kestrel::channel
