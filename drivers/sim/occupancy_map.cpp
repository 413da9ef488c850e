#include "drivers/sim/occupancy_map.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <opencv2/imgproc.hpp>

#include "common/error.h"
#include "common/text.h"
#include "common/image/image_io.h"

namespace kestrel::sim {
namespace {

// Line (1-based) of a node, for messages.
int line_of(const YAML::Node& node) { return node.Mark().line + 1; }

double number(const YAML::Node& root, const std::string& path, const char* key) {
  const YAML::Node n = root[key];
  try {
    const double v = n.as<double>();
    if (!std::isfinite(v)) throw YAML::Exception(n.Mark(), "not finite");
    return v;
  } catch (const YAML::Exception&) {
    throw InputError(at_line(path, line_of(n), std::string("'") + key + "' must be a number"));
  }
}

// The image's size against the bounds (occupancy_map.h), before it is decoded.
void check_image_size(const OccupancyMap& map, int image_line, int resolution_line) {
  const std::string& path = map.yaml_path;
  const std::string image = "map image '" + map.image_path + "'";
  image::Header header;
  try {
    header = image::read_header(map.image_path);
  } catch (const InputError&) {
    throw InputError(at_line(path, image_line, "cannot read " + image));
  }
  if (header.format == image::Format::kUnknown)
    throw InputError(at_line(path, image_line, image + " is not a PNG or PNM (PGM, PPM, PBM) file"));
  const std::string size = std::to_string(header.width) + " x " + std::to_string(header.height) + " pixels";
  if (header.width <= 0 || header.height <= 0)
    throw InputError(at_line(path, image_line, image + " has no pixels (" + size + ")"));
  if (static_cast<double>(header.width) * static_cast<double>(header.height) > static_cast<double>(kMaxMapPixels))
    throw InputError(at_line(path, image_line, image + " is " + size + ", more than the " +
                                                   std::to_string(kMaxMapPixels) + " a map may have"));
  const double width_m = static_cast<double>(header.width) * map.resolution;
  const double height_m = static_cast<double>(header.height) * map.resolution;
  if (std::max(width_m, height_m) > kMaxMapSide_m)
    throw InputError(at_line(path, resolution_line,
                             "'resolution' " + number_text(map.resolution) + " m per pixel makes the " + size +
                                 " of " + image + " " + number_text(width_m) + " x " + number_text(height_m) +
                                 " m; a map spans at most " + number_text(kMaxMapSide_m) + " m"));
}

}  // namespace

cv::Mat OccupancyMap::free_mask() const {
  cv::Mat mask(image.size(), CV_8UC1);
  for (int r = 0; r < image.rows; ++r) {
    const uchar* in = image.ptr<uchar>(r);
    uchar* out = mask.ptr<uchar>(r);
    for (int c = 0; c < image.cols; ++c) {
      const double p = negate ? in[c] / 255.0 : (255 - in[c]) / 255.0;
      out[c] = p < free_thresh ? 255 : 0;
    }
  }
  return mask;
}

Eigen::Affine2d OccupancyMap::T_world_pixel() const {
  // Pixel (col, row) -> map metres with y up from the bottom edge, then the origin pose.
  Eigen::Affine2d T_map_pixel = Eigen::Affine2d::Identity();
  T_map_pixel.linear() << resolution, 0, 0, -resolution;
  T_map_pixel.translation() << 0.5 * resolution, (image.rows - 0.5) * resolution;
  Eigen::Affine2d T_world_map = Eigen::Affine2d::Identity();
  T_world_map.linear() = Eigen::Rotation2Dd(origin.z()).toRotationMatrix();
  T_world_map.translation() = origin.head<2>();
  return T_world_map * T_map_pixel;
}

OccupancyMap read_occupancy_map(const std::string& yaml_path) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(yaml_path);
  } catch (const YAML::BadFile&) {
    throw InputError(yaml_path + ": cannot open map file");
  } catch (const YAML::Exception& e) {
    throw InputError(at_line(yaml_path, e.mark.line + 1, "not valid YAML: " + e.msg));
  }
  if (!root.IsMap()) throw InputError(at_line(yaml_path, 1, "expected a YAML mapping of map keys"));
  for (const char* key : {"image", "resolution", "origin"}) {
    if (!root[key]) throw InputError(yaml_path + ": missing key '" + std::string(key) + "'");
  }
  OccupancyMap map;
  map.yaml_path = yaml_path;
  map.resolution = number(root, yaml_path, "resolution");
  if (!(map.resolution >= kMinMapResolution_m && map.resolution <= kMaxMapResolution_m))
    throw InputError(at_line(yaml_path, line_of(root["resolution"]),
                             "'resolution' must be in [" + number_text(kMinMapResolution_m) + ", " +
                                 number_text(kMaxMapResolution_m) + "] m per pixel, got " +
                                 number_text(map.resolution)));
  const YAML::Node origin = root["origin"];
  if (!origin.IsSequence() || origin.size() != 3)
    throw InputError(at_line(yaml_path, line_of(origin), "'origin' must be a list [x, y, yaw]"));
  for (size_t i = 0; i < 3; ++i) {
    try {
      map.origin[static_cast<int>(i)] = origin[i].as<double>();
    } catch (const YAML::Exception&) {
      throw InputError(at_line(yaml_path, line_of(origin), "'origin' values must be numbers"));
    }
    if (!std::isfinite(map.origin[static_cast<int>(i)]))
      throw InputError(at_line(yaml_path, line_of(origin), "'origin' values must be finite"));
  }
  if (std::max(std::abs(map.origin.x()), std::abs(map.origin.y())) > kMaxMapOrigin_m)
    throw InputError(at_line(yaml_path, line_of(origin),
                             "'origin' x and y must be within +-" + number_text(kMaxMapOrigin_m) + " m, got [" +
                                 number_text(map.origin.x()) + ", " + number_text(map.origin.y()) + "]"));
  if (root["negate"]) map.negate = number(root, yaml_path, "negate") != 0;
  if (root["occupied_thresh"]) map.occupied_thresh = number(root, yaml_path, "occupied_thresh");
  if (root["free_thresh"]) map.free_thresh = number(root, yaml_path, "free_thresh");
  if (!(map.free_thresh >= 0 && map.free_thresh < map.occupied_thresh && map.occupied_thresh <= 1))
    throw InputError(at_line(yaml_path, line_of(root["free_thresh"] ? root["free_thresh"] : root["occupied_thresh"]),
                             "need 0 <= free_thresh < occupied_thresh <= 1"));
  if (root["mode"]) {
    const std::string mode = root["mode"].as<std::string>("");
    if (mode != "trinary" && mode != "scale")
      throw InputError(at_line(yaml_path, line_of(root["mode"]), "unsupported mode '" + mode + "' (trinary or scale)"));
  }
  std::string image;
  try {
    image = root["image"].as<std::string>();
  } catch (const YAML::Exception&) {
    throw InputError(at_line(yaml_path, line_of(root["image"]), "'image' must be a file name"));
  }
  std::filesystem::path image_path(image);
  if (image_path.is_relative()) image_path = std::filesystem::path(yaml_path).parent_path() / image_path;
  map.image_path = image_path.string();
  check_image_size(map, line_of(root["image"]), line_of(root["resolution"]));
  cv::Mat raw;
  try {
    raw = image::read_image(map.image_path);
  } catch (const InputError& e) {
    throw InputError(at_line(yaml_path, line_of(root["image"]), std::string("cannot read map image: ") + e.what()));
  }
  if (raw.depth() != CV_8U)
    throw InputError(at_line(yaml_path, line_of(root["image"]), "map image '" + map.image_path + "' is not 8-bit"));
  if (raw.channels() == 1) map.image = raw;
  else if (raw.channels() == 3) cv::cvtColor(raw, map.image, cv::COLOR_BGR2GRAY);
  else if (raw.channels() == 4) cv::cvtColor(raw, map.image, cv::COLOR_BGRA2GRAY);
  else throw InputError(at_line(yaml_path, line_of(root["image"]), "map image has an unsupported channel count"));
  return map;
}

}  // namespace kestrel::sim
