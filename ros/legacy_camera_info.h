#pragma once
// sensor_msgs/CameraInfo as ROS defined it before Electric (2011): what TUM RGB-D's bags,
// recorded in 2011, may carry. Its fields are the same calibration in another layout (no
// distortion_model, D of exactly five plumb-bob coefficients, no binning), so librosbag's
// instantiate<sensor_msgs::CameraInfo> refuses it by MD5. Read through ROS's own serializer
// with this layout, only when the bag's stored definition of the topic is field for field the
// old one (is_pre_electric_camera_info): never guessed from the bytes.

#include <boost/array.hpp>
#include <cstdint>
#include <string>

#include <ros/message_traits.h>
#include <ros/serialization.h>
#include <sensor_msgs/CameraInfo.h>
#include <std_msgs/Header.h>

namespace kestrel::ros1::legacy {

struct CameraInfo {
  std_msgs::Header header;
  uint32_t height = 0;
  uint32_t width = 0;
  uint32_t roi_x_offset = 0, roi_y_offset = 0, roi_height = 0, roi_width = 0;
  boost::array<double, 5> D{};
  boost::array<double, 9> K{};
  boost::array<double, 9> R{};
  boost::array<double, 12> P{};
};

/// True when `definition` (a bag connection's message definition, the main message's text
/// and, after "====" lines, its dependencies') has exactly the fields of the pre-Electric
/// CameraInfo and RegionOfInterest; comments, constants and blank lines aside.
bool is_pre_electric_camera_info(const std::string& definition);

/// The same calibration as today's message (distortion_model "plumb_bob").
sensor_msgs::CameraInfo to_current(const CameraInfo& old);

}  // namespace kestrel::ros1::legacy

namespace ros {
namespace message_traits {
// MD5 "*": librosbag's instantiate then takes any definition; the importer has checked it.
template <>
struct MD5Sum<kestrel::ros1::legacy::CameraInfo> {
  static const char* value() { return "*"; }
  static const char* value(const kestrel::ros1::legacy::CameraInfo&) { return value(); }
};
template <>
struct DataType<kestrel::ros1::legacy::CameraInfo> {
  static const char* value() { return "sensor_msgs/CameraInfo"; }
  static const char* value(const kestrel::ros1::legacy::CameraInfo&) { return value(); }
};
}  // namespace message_traits
namespace serialization {
template <>
struct Serializer<kestrel::ros1::legacy::CameraInfo> {
  template <typename Stream, typename T>
  inline static void allInOne(Stream& stream, T m) {
    stream.next(m.header);
    stream.next(m.height);
    stream.next(m.width);
    stream.next(m.roi_x_offset);
    stream.next(m.roi_y_offset);
    stream.next(m.roi_height);
    stream.next(m.roi_width);
    stream.next(m.D);
    stream.next(m.K);
    stream.next(m.R);
    stream.next(m.P);
  }
  ROS_DECLARE_ALLINONE_SERIALIZER
};
}  // namespace serialization
}  // namespace ros
