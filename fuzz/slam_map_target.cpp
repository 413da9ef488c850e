// A saved SLAM map (slam/map/map_file.h), as `kestrel-slam --map` reads it and a Slam goes on
// from it: refused with InputError or read whole, never a crash or an allocation beyond the file.
// The sections' CRCs are made right before reading (a mutated byte would otherwise stop at the
// checksum every time): what is fuzzed is everything the checksum does not guard against, a
// crafted file.

#include <cstring>
#include <filesystem>
#include <memory>
#include <random>

#include "common/crc32.h"
#include "fuzz/groups.h"
#include "slam/backend/slam.h"
#include "slam/map/map_file.h"

namespace kestrel::fuzz {
namespace {

constexpr size_t kMagicAndVersion = 16 + 4;
constexpr size_t kSectionHead = 12, kSectionTail = 4;

// Rewrites each section's CRC over its tag, size and payload, as far as the framing goes.
Bytes with_checksums(const uint8_t* data, size_t size) {
  Bytes b(data, data + size);
  size_t at = kMagicAndVersion;
  while (at <= b.size() && b.size() - at >= kSectionHead + kSectionTail) {
    uint64_t length;
    std::memcpy(&length, b.data() + at + 4, 8);
    if (length > b.size() - at - kSectionHead - kSectionTail) break;
    const uint32_t crc = crc32(b.data() + at + kSectionHead, length, crc32(b.data() + at, kSectionHead));
    std::memcpy(b.data() + at + kSectionHead + length, &crc, 4);
    at += kSectionHead + length + kSectionTail;
  }
  return b;
}

bool run_slam_map(const uint8_t* data, size_t size) {
  const Bytes fixed = with_checksums(data, size);
  const std::filesystem::path dir = std::filesystem::path(scratch_file("slam.map", fixed.data(), fixed.size())).parent_path();
  return accepted([&] {
    auto map = std::make_shared<const slam::SlamMap>(slam::read_map(dir.string()));
    // What a process does next: go on from it (every keyframe into place recognition).
    const slam::Slam slam(map, slam::SlamOptions{});
    if (slam.keyframes().size() != map->keyframes.size()) defect("slam-map", "keyframes lost on restore");
  });
}

// A map as kestrel-slam writes it: two keyframes of random features, an odometry edge between
// them, and a small vocabulary trained on their descriptors.
std::vector<Bytes> slam_map_seeds() {
  std::mt19937 rng(7);
  slam::SlamMap map;
  std::vector<cv::Mat> images;
  for (int k = 0; k < 2; ++k) {
    slam::Keyframe kf;
    kf.id = k;
    kf.utime = 1'000'000 + 500'000 * k;
    kf.T_odom_camera.translation().x() = 0.3 * k;
    kf.sensor.name = "simulator";
    kf.features.camera = PinholeCamera::vga(525, 525, 319.5, 239.5);
    kf.features.descriptors = cv::Mat(12, 32, CV_8UC1);
    for (int i = 0; i < 12; ++i) {
      kf.features.keypoints.emplace_back(static_cast<float>(20 + 40 * i), 100.0f + k, 31.0f);
      kf.features.points.emplace_back(0.1 * i, 0.05, 2.0);
      for (int j = 0; j < 32; ++j) kf.features.descriptors.at<uint8_t>(i, j) = static_cast<uint8_t>(rng());
    }
    images.push_back(kf.features.descriptors);
    map.graph.add_vertex(k, kf.T_odom_camera, k == 0);
    map.keyframes.push_back(std::move(kf));
  }
  map.graph.add_edge(0, 1, map.keyframes[0].T_odom_camera.inverse() * map.keyframes[1].T_odom_camera,
                     Matrix6d::Identity() * 100.0, slam::EdgeKind::kOdometry);
  map.gate_information.push_back(Matrix6d::Identity());
  map.vocabulary = std::make_shared<const slam::Vocabulary>(slam::Vocabulary::train(images, {2, 2, 5}, 1));
  map.sessions = 1;
  map.revision = 3;
  const std::string dir = scratch_dir() + "/seed-map";
  slam::write_map(dir, map, {"fuzz seed", ""});
  return {file_bytes(slam::map_file_in(dir))};
}

}  // namespace

std::vector<Target> slam_map_targets() {
  return {{"slam-map", "a saved SLAM map (kestrel-slam --map DIR), read and gone on from", &run_slam_map,
           &slam_map_seeds}};
}

}  // namespace kestrel::fuzz
