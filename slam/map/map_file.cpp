#include "slam/map/map_file.h"

#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <type_traits>
#include <vector>

#include "common/atomic_file.h"
#include "common/crc32.h"
#include "common/error.h"

namespace kestrel::slam {
namespace {

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__, "the SLAM map format is little-endian");

constexpr char kMagic[] = "KESTREL-SLAM-MAP";
constexpr size_t kMagicSize = sizeof(kMagic) - 1;
constexpr size_t kSectionHead = 4 + 8;  // tag, size
constexpr size_t kSectionTail = 4;      // CRC

// Bytes of one section's payload, appended field by field.
class Writer {
 public:
  template <class T>
  void put(const T& v) {
    static_assert(std::is_trivially_copyable_v<T>);
    const auto* p = reinterpret_cast<const uint8_t*>(&v);
    bytes.insert(bytes.end(), p, p + sizeof(T));
  }
  void put_bytes(const void* data, size_t n) {
    const auto* p = static_cast<const uint8_t*>(data);
    bytes.insert(bytes.end(), p, p + n);
  }
  void put_string(const std::string& s) {
    put(static_cast<uint32_t>(s.size()));
    put_bytes(s.data(), s.size());
  }
  void put_pose(const Eigen::Isometry3d& T) {
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) put(T.matrix()(r, c));
  }
  void put_matrix6(const Matrix6d& M) { put_bytes(M.data(), sizeof(double) * 36); }
  std::vector<uint8_t> bytes;
};

// A section's payload, read with every size checked against what is left: a damaged count
// is an error, never an allocation.
class Reader {
 public:
  Reader(const uint8_t* data, size_t size, std::string what) : p_(data), end_(data + size), what_(std::move(what)) {}
  template <class T>
  T get() {
    static_assert(std::is_trivially_copyable_v<T>);
    T v;
    std::memcpy(&v, take(sizeof(T)), sizeof(T));
    return v;
  }
  const uint8_t* take(size_t n) {
    if (static_cast<size_t>(end_ - p_) < n) fail("is cut short");
    const uint8_t* at = p_;
    p_ += n;
    return at;
  }
  /// A count of items of at least `item_bytes` each that the rest can hold.
  size_t count(size_t item_bytes) {
    const auto n = get<uint32_t>();
    if (item_bytes > 0 && n > left() / item_bytes) fail("holds a count larger than its bytes (" + std::to_string(n) + ")");
    return n;
  }
  std::string get_string() {
    const size_t n = count(1);
    const uint8_t* s = take(n);
    return std::string(reinterpret_cast<const char*>(s), n);
  }
  Eigen::Isometry3d get_pose() {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) T.matrix()(r, c) = get<double>();
    return T;
  }
  Matrix6d get_matrix6() {
    Matrix6d M;
    std::memcpy(M.data(), take(sizeof(double) * 36), sizeof(double) * 36);
    return M;
  }
  size_t left() const { return static_cast<size_t>(end_ - p_); }
  [[noreturn]] void fail(const std::string& why) const { throw InputError(what_ + " " + why); }

 private:
  const uint8_t* p_;
  const uint8_t* end_;
  std::string what_;
};

uint32_t tag_of(const char (&name)[5]) {
  uint32_t t;
  std::memcpy(&t, name, 4);
  return t;
}

void put_section(std::ostream& out, const char (&name)[5], const std::vector<uint8_t>& payload) {
  Writer head;
  head.put(tag_of(name));
  head.put(static_cast<uint64_t>(payload.size()));
  uint32_t crc = crc32(head.bytes.data(), head.bytes.size());
  crc = crc32(payload.data(), payload.size(), crc);
  out.write(reinterpret_cast<const char*>(head.bytes.data()), static_cast<std::streamsize>(head.bytes.size()));
  out.write(reinterpret_cast<const char*>(payload.data()), static_cast<std::streamsize>(payload.size()));
  out.write(reinterpret_cast<const char*>(&crc), sizeof(crc));
}

// Keypoint: pt, size, angle, response (float), octave, class_id (int32); descriptor; point.
constexpr size_t kFeatureBytes = 5 * 4 + 2 * 4 + 32 + 3 * 8;

std::vector<uint8_t> keyframes_section(const SlamMap& map) {
  Writer w;
  w.put(static_cast<uint32_t>(map.keyframes.size()));
  for (const Keyframe& kf : map.keyframes) {
    w.put(kf.id);
    w.put(kf.utime);
    w.put(static_cast<int32_t>(kf.session));
    w.put(static_cast<uint8_t>(kf.link));
    w.put(static_cast<uint8_t>(kf.thinned ? 1 : 0));
    w.put_pose(kf.T_odom_camera);
    w.put_pose(kf.T_body_camera);
    w.put_pose(kf.T_camera_depth);
    // Of the camera's profile SLAM uses the name and the loops' noise floor (loop_verifier.h).
    w.put_string(kf.sensor.name);
    const auto& floor = kf.sensor.slam.loop_rotation_floor_rad;
    w.put(static_cast<uint8_t>(floor ? 1 : 0));
    w.put(floor.value_or(0.0));
    const PinholeCamera& c = kf.features.camera;
    w.put(static_cast<int32_t>(c.width));
    w.put(static_cast<int32_t>(c.height));
    for (double v : {c.fx, c.fy, c.cx, c.cy}) w.put(v);
    for (double v : c.distortion) w.put(v);
    const FrameFeatures& f = kf.features;
    w.put(static_cast<uint32_t>(f.size()));
    for (size_t i = 0; i < f.size(); ++i) {
      const cv::KeyPoint& k = f.keypoints[i];
      for (float v : {k.pt.x, k.pt.y, k.size, k.angle, k.response}) w.put(v);
      w.put(static_cast<int32_t>(k.octave));
      w.put(static_cast<int32_t>(k.class_id));
      w.put_bytes(f.descriptors.ptr<uint8_t>(static_cast<int>(i)), 32);
      for (int a = 0; a < 3; ++a) w.put(f.points[i][a]);
    }
  }
  return w.bytes;
}

std::vector<uint8_t> graph_section(const SlamMap& map) {
  Writer w;
  const PoseGraph3d& g = map.graph;
  w.put(static_cast<uint32_t>(g.poses.size()));
  for (size_t v = 0; v < g.poses.size(); ++v) {
    w.put(g.ids[v]);
    w.put_pose(g.poses[v]);
    w.put(static_cast<uint8_t>(g.fixed[v]));
  }
  w.put(static_cast<uint32_t>(g.edges.size()));
  for (size_t e = 0; e < g.edges.size(); ++e) {
    const auto& edge = g.edges[e];
    w.put(static_cast<int32_t>(edge.from));
    w.put(static_cast<int32_t>(edge.to));
    w.put(static_cast<uint8_t>(edge.kind));
    w.put_pose(edge.measurement);
    w.put_matrix6(edge.information);
    w.put_matrix6(map.gate_information[e]);
  }
  w.put(map.revision);
  return w.bytes;
}

std::string head_text(const SlamMap& map, const MapProvenance& provenance) {
  int thinned = 0;
  for (const Keyframe& kf : map.keyframes) thinned += kf.thinned ? 1 : 0;
  std::ostringstream s;
  s << "format: " << kMapFormatVersion << "\n"
    << "made_by: " << provenance.made_by << "\n"
    << "created: " << provenance.created << "\n"
    << "keyframes: " << map.keyframes.size() << "\n"
    << "thinned: " << thinned << "\n"
    << "edges: " << map.graph.edges.size() << "\n"
    << "sessions: " << map.sessions << "\n"
    << "vocabulary_words: " << (map.vocabulary ? map.vocabulary->num_words() : 0) << "\n";
  return s.str();
}

void read_keyframes(Reader& r, SlamMap& map) {
  const size_t n = r.count(8 + 8 + 4 + 2 + 3 * 96);
  map.keyframes.resize(n);
  for (size_t k = 0; k < n; ++k) {
    Keyframe& kf = map.keyframes[k];
    kf.id = r.get<int64_t>();
    kf.utime = r.get<int64_t>();
    kf.session = r.get<int32_t>();
    // Sessions number the flights that made the keyframes: never more than the keyframes.
    if (kf.session < 0 || static_cast<size_t>(kf.session) >= n) r.fail("has keyframe " + std::to_string(k) + " of an impossible session");
    const auto link = r.get<uint8_t>();
    if (link > static_cast<uint8_t>(OdometryLink::kBroken)) r.fail("has keyframe " + std::to_string(k) + " with an unknown link");
    kf.link = static_cast<OdometryLink>(link);
    kf.thinned = r.get<uint8_t>() != 0;
    kf.T_odom_camera = r.get_pose();
    kf.T_body_camera = r.get_pose();
    kf.T_camera_depth = r.get_pose();
    kf.sensor.name = r.get_string();
    const bool has_floor = r.get<uint8_t>() != 0;
    const double floor = r.get<double>();
    if (has_floor) {
      if (!(std::isfinite(floor) && floor >= 0.0)) r.fail("has keyframe " + std::to_string(k) + " with a bad loop floor");
      kf.sensor.slam.loop_rotation_floor_rad = floor;
    }
    PinholeCamera& c = kf.features.camera;
    c.width = r.get<int32_t>();
    c.height = r.get<int32_t>();
    for (double* v : {&c.fx, &c.fy, &c.cx, &c.cy}) *v = r.get<double>();
    for (double& v : c.distortion) v = r.get<double>();
    if (c.width <= 0 || c.height <= 0 || !(c.fx > 0.0 && c.fy > 0.0 && std::isfinite(c.fx) && std::isfinite(c.fy)) ||
        !std::isfinite(c.cx) || !std::isfinite(c.cy)) {
      r.fail("has keyframe " + std::to_string(k) + " with an impossible camera");
    }
    const size_t m = r.count(kFeatureBytes);
    FrameFeatures& f = kf.features;
    f.keypoints.resize(m);
    f.points.resize(m);
    f.descriptors = cv::Mat(static_cast<int>(m), 32, CV_8UC1);
    for (size_t i = 0; i < m; ++i) {
      cv::KeyPoint& kp = f.keypoints[i];
      for (float* v : {&kp.pt.x, &kp.pt.y, &kp.size, &kp.angle, &kp.response}) *v = r.get<float>();
      kp.octave = r.get<int32_t>();
      kp.class_id = r.get<int32_t>();
      std::memcpy(f.descriptors.ptr<uint8_t>(static_cast<int>(i)), r.take(32), 32);
      for (int a = 0; a < 3; ++a) f.points[i][a] = r.get<double>();
      if (!std::isfinite(kp.pt.x) || !std::isfinite(kp.pt.y)) r.fail("has a keypoint that is not finite");
    }
    if (m == 0) f.descriptors = cv::Mat();
  }
}

void read_graph(Reader& r, SlamMap& map) {
  PoseGraph3d& g = map.graph;
  const size_t n = r.count(8 + 96 + 1);
  for (size_t v = 0; v < n; ++v) {
    const auto id = r.get<int64_t>();
    const Eigen::Isometry3d pose = r.get_pose();
    g.add_vertex(id, pose, r.get<uint8_t>() != 0);
  }
  const size_t m = r.count(4 + 4 + 1 + 96 + 2 * 288);
  map.gate_information.reserve(m);
  for (size_t e = 0; e < m; ++e) {
    const auto from = r.get<int32_t>();
    const auto to = r.get<int32_t>();
    const auto kind = r.get<uint8_t>();
    if (kind > static_cast<uint8_t>(EdgeKind::kLoopClosure)) r.fail("has an edge of unknown kind");
    const Eigen::Isometry3d measurement = r.get_pose();
    const Matrix6d information = r.get_matrix6();
    g.add_edge(from, to, measurement, information, static_cast<EdgeKind>(kind));
    map.gate_information.push_back(r.get_matrix6());
  }
  map.revision = r.get<int64_t>();
  if (map.revision < 0) r.fail("has a negative revision");
}

}  // namespace

std::string map_file_in(const std::string& dir) { return (std::filesystem::path(dir) / "slam.map").string(); }

void write_map(const std::string& dir, const SlamMap& map, const MapProvenance& provenance) {
  check_map(map, "slam map to save in " + dir);
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) throw InputError(dir + ": cannot create the map's folder (" + ec.message() + ")");
  std::ostringstream vocabulary(std::ios::binary);
  if (map.vocabulary && !map.vocabulary->empty()) map.vocabulary->write(vocabulary);
  const std::string head = head_text(map, provenance);
  const std::string vocabulary_bytes = vocabulary.str();
  AtomicFile file(map_file_in(dir));
  std::ostream& out = file.stream();
  out.write(kMagic, kMagicSize);
  const auto version = static_cast<uint32_t>(kMapFormatVersion);
  out.write(reinterpret_cast<const char*>(&version), sizeof(version));
  put_section(out, "HEAD", std::vector<uint8_t>(head.begin(), head.end()));
  put_section(out, "VOCB", std::vector<uint8_t>(vocabulary_bytes.begin(), vocabulary_bytes.end()));
  put_section(out, "KEYF", keyframes_section(map));
  put_section(out, "GRPH", graph_section(map));
  put_section(out, "END.", {});
  file.commit();
}

SlamMap read_map(const std::string& dir, std::string* head) {
  const std::string path = map_file_in(dir);
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw InputError(path + ": no SLAM map here (" +
                     (std::filesystem::exists(dir, ec) ? "the folder has no slam.map" : "no such folder") + ")");
  }
  std::ifstream in(path, std::ios::binary);
  const std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in.good() && !in.eof()) throw InputError(path + ": cannot be read");
  if (bytes.size() < kMagicSize + 4 || std::memcmp(bytes.data(), kMagic, kMagicSize) != 0) {
    throw InputError(path + ": not a kestrel SLAM map (no \"" + std::string(kMagic) + "\" at its start)");
  }
  uint32_t version;
  std::memcpy(&version, bytes.data() + kMagicSize, 4);
  if (version != kMapFormatVersion) {
    throw InputError(path + ": SLAM map format " + std::to_string(version) + ", this kestrel reads format " +
                     std::to_string(kMapFormatVersion) + (version > kMapFormatVersion ? " (made by a newer kestrel)" : ""));
  }
  SlamMap map;
  size_t at = kMagicSize + 4;
  bool seen_head = false, seen_vocabulary = false, seen_keyframes = false, seen_graph = false, ended = false;
  while (!ended) {
    if (bytes.size() - at < kSectionHead + kSectionTail) throw InputError(path + ": is cut short (no end section)");
    uint32_t tag;
    uint64_t size;
    std::memcpy(&tag, bytes.data() + at, 4);
    std::memcpy(&size, bytes.data() + at + 4, 8);
    const std::string name(reinterpret_cast<const char*>(&tag), 4);
    const std::string what = path + ": section " + (std::isprint(static_cast<unsigned char>(name[0])) ? name : "?") +
                             " at byte " + std::to_string(at);
    if (size > bytes.size() - at - kSectionHead - kSectionTail) throw InputError(what + " is cut short");
    const uint8_t* payload = bytes.data() + at + kSectionHead;
    uint32_t stored_crc;
    std::memcpy(&stored_crc, payload + size, 4);
    if (crc32(payload, size, crc32(bytes.data() + at, kSectionHead)) != stored_crc) {
      throw InputError(what + " fails its checksum (the file is damaged)");
    }
    Reader r(payload, size, what);
    const bool repeated = (tag == tag_of("HEAD") && seen_head) || (tag == tag_of("VOCB") && seen_vocabulary) ||
                          (tag == tag_of("KEYF") && seen_keyframes) || (tag == tag_of("GRPH") && seen_graph);
    if (repeated) throw InputError(what + " comes twice");
    if (tag == tag_of("END.") && size != 0) throw InputError(what + " has content (an end section has none)");
    if (tag == tag_of("HEAD")) {
      if (head) *head = std::string(reinterpret_cast<const char*>(payload), size);
      seen_head = true;
    } else if (tag == tag_of("VOCB")) {
      if (size > 0) {
        std::istringstream v(std::string(reinterpret_cast<const char*>(payload), size), std::ios::binary);
        map.vocabulary = std::make_shared<const Vocabulary>(Vocabulary::read(v, what));
      } else {
        map.vocabulary = std::make_shared<const Vocabulary>();
      }
      seen_vocabulary = true;
    } else if (tag == tag_of("KEYF")) {
      read_keyframes(r, map);
      seen_keyframes = true;
    } else if (tag == tag_of("GRPH")) {
      read_graph(r, map);
      seen_graph = true;
    } else if (tag == tag_of("END.")) {
      ended = true;
    } else {
      throw InputError(what + " is of an unknown kind");
    }
    if (tag != tag_of("HEAD") && tag != tag_of("VOCB") && r.left() != 0 && tag != tag_of("END.")) {
      throw InputError(what + " has " + std::to_string(r.left()) + " bytes after its content");
    }
    at += kSectionHead + size + kSectionTail;
  }
  if (at != bytes.size()) throw InputError(path + ": has bytes after its end section");
  if (!seen_head || !seen_vocabulary || !seen_keyframes || !seen_graph) {
    throw InputError(path + ": lacks a section (HEAD, VOCB, KEYF and GRPH are all needed)");
  }
  int sessions = 0;
  for (const Keyframe& kf : map.keyframes) sessions = std::max(sessions, kf.session + 1);
  map.sessions = sessions;
  check_map(map, path);
  return map;
}

}  // namespace kestrel::slam
