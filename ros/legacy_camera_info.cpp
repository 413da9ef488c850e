#include "ros/legacy_camera_info.h"

#include <sstream>
#include <vector>

namespace kestrel::ros1::legacy {
namespace {

// The field lines ("type name") of one message's definition text, in order.
std::vector<std::string> fields_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    line = line.substr(0, line.find('#'));
    std::istringstream words(line);
    std::string type, name, extra;
    if (!(words >> type >> name)) continue;  // blank or comment
    if (name.find('=') != std::string::npos || (words >> extra && extra.front() == '=')) continue;  // a constant
    // Types are written relative to their package in .msg files, absolute in some definitions.
    for (const char* package : {"std_msgs/", "sensor_msgs/"})
      if (type.rfind(package, 0) == 0) type = type.substr(std::char_traits<char>::length(package));
    out.push_back(type + " " + name);
  }
  return out;
}

}  // namespace

bool is_pre_electric_camera_info(const std::string& definition) {
  // Sections: the message's own text, then "=====...\nMSG: pkg/Type\n..." per dependency.
  std::vector<std::string> sections(1);
  std::istringstream in(definition);
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("====", 0) == 0) {
      sections.emplace_back();
      continue;
    }
    sections.back() += line + "\n";
  }
  const std::vector<std::string> camera_info = {"Header header",       "uint32 height",     "uint32 width",
                                                "RegionOfInterest roi", "float64[5] D",      "float64[9] K",
                                                "float64[9] R",         "float64[12] P"};
  const std::vector<std::string> roi = {"uint32 x_offset", "uint32 y_offset", "uint32 height", "uint32 width"};
  if (fields_of(sections.front()) != camera_info) return false;
  for (size_t i = 1; i < sections.size(); ++i) {
    const std::string& s = sections[i];
    if (s.rfind("MSG: sensor_msgs/RegionOfInterest\n", 0) == 0) return fields_of(s.substr(s.find('\n') + 1)) == roi;
  }
  return false;
}

sensor_msgs::CameraInfo to_current(const CameraInfo& old) {
  sensor_msgs::CameraInfo m;
  m.header = old.header;
  m.height = old.height;
  m.width = old.width;
  m.distortion_model = "plumb_bob";
  m.D.assign(old.D.begin(), old.D.end());
  m.K = old.K;
  m.R = old.R;
  m.P = old.P;
  m.roi.x_offset = old.roi_x_offset;
  m.roi.y_offset = old.roi_y_offset;
  m.roi.height = old.roi_height;
  m.roi.width = old.roi_width;
  return m;
}

}  // namespace kestrel::ros1::legacy
