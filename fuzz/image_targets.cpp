// Image files a user gives: PNG and PNM as every reader decodes them, a TUM sequence's depth
// and colour images as its player loads them, and ROS map_server maps (YAML + image) as the
// planner and the simulator read them.

#include <algorithm>
#include <cstring>
#include <opencv2/core.hpp>

#include "common/error.h"
#include "common/image/image_io.h"
#include "drivers/tum/tum_images.h"
#include "fuzz/groups.h"
#include "planner/map_sources.h"

namespace kestrel::fuzz {
namespace {

Bytes bytes_of(const uint8_t* data, size_t size) { return Bytes(data, data + size); }

// A decoded image is never empty and has the size its header said (image_io.h).
void check_decoded(const char* target, const Bytes& bytes, const cv::Mat& image) {
  if (image.empty()) defect(target, "an accepted image decoded empty");
  const image::Header h = image::parse_header(bytes);
  if (h.width != image.cols || h.height != image.rows) defect(target, "a decoded image's size differs from its header's");
}

bool run_png(const uint8_t* data, size_t size) {
  const Bytes bytes = bytes_of(data, size);
  return accepted([&] { check_decoded("png", bytes, image::decode_png(bytes)); });
}

// Images of each layout the readers take: grey 8 and 16 bit, colour, colour with alpha.
std::vector<cv::Mat> sample_images() {
  cv::Mat grey(12, 16, CV_8UC1), depth(12, 16, CV_16UC1), colour(12, 16, CV_8UC3), rgba(12, 16, CV_8UC4);
  for (int v = 0; v < 12; ++v) {
    for (int u = 0; u < 16; ++u) {
      grey.at<uint8_t>(v, u) = static_cast<uint8_t>(16 * u + v);
      depth.at<uint16_t>(v, u) = static_cast<uint16_t>(u == 3 ? 0 : 5000 + 300 * u + 17 * v);
      colour.at<cv::Vec3b>(v, u) = cv::Vec3b(static_cast<uint8_t>(u * 9), static_cast<uint8_t>(v * 20), 128);
      rgba.at<cv::Vec4b>(v, u) = cv::Vec4b(static_cast<uint8_t>(u * 9), static_cast<uint8_t>(v * 20), 7, static_cast<uint8_t>(u * v));
    }
  }
  return {grey, depth, colour, rgba};
}

std::vector<Bytes> png_seeds() {
  std::vector<Bytes> out;
  for (const cv::Mat& m : sample_images()) out.push_back(image::encode_png(m, 1));
  return out;
}

bool run_pnm(const uint8_t* data, size_t size) {
  const Bytes bytes = bytes_of(data, size);
  return accepted([&] { check_decoded("pnm", bytes, image::decode_pnm(bytes)); });
}

std::vector<Bytes> pnm_seeds() {
  Bytes p5 = text("P5\n# a map\n4 2\n255\n");
  for (uint8_t v : {0, 254, 255, 128, 10, 20, 30, 40}) p5.push_back(v);
  Bytes p6 = text("P6 2 1 65535\n");
  for (int i = 0; i < 12; ++i) p6.push_back(static_cast<uint8_t>(i * 21));
  Bytes p4 = text("P4\n10 2\n");
  for (uint8_t v : {0xF0, 0xC0, 0x0F, 0x40}) p4.push_back(v);
  return {p5, p6, p4, text("P2\n3 2\n15\n0 7 15\n15 7 0\n"), text("P1\n# bits\n3 1\n1 0 1\n"),
          text("P3 1 2 255  255 0 0  0 0 255\n")};
}

// The TUM player's path: the header gives the size the list's camera would have; the depth
// image is then converted to millimetres, the colour one loaded as RGB.
bool run_tum_images(const uint8_t* data, size_t size) {
  const Bytes bytes = bytes_of(data, size);
  const image::Header h = image::parse_header(bytes);
  const int width = static_cast<int>(std::clamp<int64_t>(h.width, 1, 8192));
  const int height = static_cast<int>(std::clamp<int64_t>(h.height, 1, 8192));
  const std::string path = scratch_file("image.png", data, size);
  const tum::ListedAt listed{"depth.txt", 3};
  const bool depth = accepted([&] {
    const cv::Mat raw = tum::load_depth_raw(path, width, height, listed);
    const cv::Mat mm = tum::DepthToMillimetres()(raw);
    if (mm.type() != CV_16UC1 || mm.size() != raw.size()) defect("tum-images", "depth in millimetres lost its layout");
  });
  const bool rgb = accepted([&] {
    const cv::Mat m = tum::load_rgb(path, width, height, listed);
    if (m.type() != CV_8UC3 || m.cols != width || m.rows != height) defect("tum-images", "a colour image lost its layout");
  });
  return depth || rgb;
}
std::vector<Bytes> tum_image_seeds() {
  const auto images = sample_images();
  return {image::encode_png(images[1], 1), image::encode_png(images[2], 1)};
}

// A map_server map: the input is the YAML, a NUL byte, then the image's bytes (written as
// map.pgm and map.png beside the YAML, whichever it names).
bool run_ros_map(const uint8_t* data, size_t size) {
  const auto* nul = static_cast<const uint8_t*>(std::memchr(data, 0, size));
  const size_t yaml_size = nul ? static_cast<size_t>(nul - data) : size;
  const uint8_t* image = nul ? nul + 1 : data + size;
  const size_t image_size = static_cast<size_t>(data + size - image);
  scratch_file("map.pgm", image, image_size);
  scratch_file("map.png", image, image_size);
  const std::string yaml = scratch_file("map.yaml", data, yaml_size);
  return accepted([&] {
    const planner::OccupancyGrid grid = planner::read_ros_map(yaml);
    (void)grid;
  });
}
std::vector<Bytes> ros_map_seeds() {
  std::vector<Bytes> out;
  const auto with_image = [&](std::string_view yaml, const Bytes& image) {
    Bytes b = text(yaml);
    b.push_back(0);
    b.insert(b.end(), image.begin(), image.end());
    out.push_back(b);
  };
  Bytes pgm = text("P5\n8 6\n255\n");
  for (int i = 0; i < 48; ++i) pgm.push_back(static_cast<uint8_t>(i % 8 == 0 || i / 8 == 0 ? 0 : i % 5 == 0 ? 205 : 254));
  with_image("image: map.pgm\nresolution: 0.05\norigin: [-0.2, -0.15, 0.0]\nnegate: 0\noccupied_thresh: 0.65\nfree_thresh: 0.196\n", pgm);
  with_image("image: map.png\nresolution: 0.1\norigin: [1.0, 2.0, 0.5]\nnegate: 1\n", image::encode_png(sample_images()[0], 1));
  return out;
}

}  // namespace

std::vector<Target> image_targets() {
  return {
      {"png", "a PNG file, as every image reader decodes it", &run_png, &png_seeds},
      {"pnm", "a PBM/PGM/PPM file, plain or binary", &run_pnm, &pnm_seeds},
      {"tum-images", "a TUM sequence's depth and colour images, as its player loads them", &run_tum_images, &tum_image_seeds},
      {"ros-map", "a ROS map_server map: YAML, a NUL byte, the image", &run_ros_map, &ros_map_seeds},
  };
}

}  // namespace kestrel::fuzz
