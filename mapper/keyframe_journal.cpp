#include "mapper/keyframe_journal.h"

#include <array>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <utility>

#include "common/error.h"
#include "common/transport/convert.h"
#include "common/transport/message.h"
#include "common/transport/rgbd_codec.h"

namespace kestrel::mapper {

namespace {

constexpr char kHeader[] = "kestrel mapper journal 1\n";
constexpr size_t kHeaderSize = sizeof(kHeader) - 1;
constexpr char kKeyframe = 'K';
constexpr char kGraph = 'G';
// Far above any record (a 640x480 frame stored undecimated is under 2 MB): a larger size
// field is damage, not a record to allocate for.
constexpr uint32_t kMaxPayload = 64u << 20;

// CRC-32 (IEEE 802.3, reflected, as zlib and PNG compute it).
uint32_t crc32(const uint8_t* data, size_t size, uint32_t crc = 0) {
  static const std::array<uint32_t, 256> table = [] {
    std::array<uint32_t, 256> t{};
    for (uint32_t i = 0; i < 256; ++i) {
      uint32_t c = i;
      for (int k = 0; k < 8; ++k) c = (c & 1u) ? 0xEDB88320u ^ (c >> 1) : c >> 1;
      t[i] = c;
    }
    return t;
  }();
  crc = ~crc;
  for (size_t i = 0; i < size; ++i) crc = table[(crc ^ data[i]) & 0xFFu] ^ (crc >> 8);
  return ~crc;
}

void put_u32(std::vector<uint8_t>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}

uint32_t get_u32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 | static_cast<uint32_t>(p[2]) << 16 |
         static_cast<uint32_t>(p[3]) << 24;
}

// The journal keeps the frame exactly: raw colour, lossless depth.
transport::RgbdEncoding lossless() {
  transport::RgbdEncoding e;
  e.rgb = kestrel::rgbd_frame_t::RGB_RGB8;
  e.depth = kestrel::rgbd_frame_t::DEPTH_U16_MM_ZSTD;
  return e;
}

JournalRecord decode_record(char kind, const std::vector<uint8_t>& payload, const std::string& what) {
  JournalRecord r;
  if (kind == kGraph) {
    r.kind = JournalRecord::Kind::kGraph;
    r.graph = transport::decode_message<kestrel::slam_graph_t>(payload.data(), payload.size(), what);
    return r;
  }
  if (kind != kKeyframe) throw InputError(what + ": unknown record kind " + std::to_string(kind));
  if (payload.size() < 4) throw InputError(what + ": keyframe record too short");
  const uint32_t size = get_u32(payload.data());
  if (size > payload.size() - 4) throw InputError(what + ": keyframe size beyond the record");
  r.kind = JournalRecord::Kind::kKeyframe;
  r.keyframe = transport::decode_message<kestrel::slam_keyframe_t>(payload.data() + 4, size, what);
  const auto frame = transport::decode_message<kestrel::rgbd_frame_t>(payload.data() + 4 + size,
                                                                      payload.size() - 4 - size, what);
  r.frame = transport::decode_rgbd(frame, what.c_str());
  return r;
}

}  // namespace

JournalContents read_journal(const std::string& path) {
  JournalContents contents;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec) || std::filesystem::file_size(path, ec) == 0) return contents;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot read the mapper journal: " + std::strerror(errno));
  std::string header(kHeaderSize, '\0');
  if (!in.read(header.data(), static_cast<std::streamsize>(kHeaderSize)) || header != kHeader) {
    throw InputError(path + ": not a kestrel mapper journal (its first line is not \"" +
                     std::string(kHeader, kHeaderSize - 1) + "\")");
  }
  contents.intact_bytes = kHeaderSize;
  std::vector<uint8_t> payload;
  for (size_t index = 0;; ++index) {
    uint8_t head[5];
    if (!in.read(reinterpret_cast<char*>(head), 5)) {
      if (in.gcount() != 0) contents.damage = "record " + std::to_string(index) + " is cut short";
      break;
    }
    const char kind = static_cast<char>(head[0]);
    const uint32_t size = get_u32(head + 1);
    if (size > kMaxPayload) {
      contents.damage = "record " + std::to_string(index) + " claims " + std::to_string(size) + " bytes";
      break;
    }
    payload.resize(size);
    uint8_t crc_bytes[4];
    if (!in.read(reinterpret_cast<char*>(payload.data()), size) || !in.read(reinterpret_cast<char*>(crc_bytes), 4)) {
      contents.damage = "record " + std::to_string(index) + " is cut short";
      break;
    }
    if (crc32(payload.data(), size, crc32(head, 5)) != get_u32(crc_bytes)) {
      contents.damage = "record " + std::to_string(index) + " fails its CRC";
      break;
    }
    try {
      contents.records.push_back(decode_record(kind, payload, path + ": record " + std::to_string(index)));
    } catch (const InputError& e) {
      contents.damage = e.what();
      break;
    }
    contents.intact_bytes += 5 + size + 4;
  }
  return contents;
}

GraphKeyframe to_graph_keyframe(const kestrel::slam_keyframe_t& keyframe, const char* what) {
  GraphKeyframe g;
  g.id = keyframe.id;
  g.utime = keyframe.utime;
  g.T_world_camera = transport::from_message(keyframe.T_world_camera, what);
  g.T_camera_depth = transport::from_message(keyframe.T_camera_depth, what);
  return g;
}

Restored restore_journal(const JournalContents& journal, Mapper& mapper, const std::string& what) {
  Restored restored;
  for (const JournalRecord& r : journal.records) {
    if (r.kind == JournalRecord::Kind::kKeyframe) {
      mapper.restore_keyframe(to_graph_keyframe(r.keyframe, what.c_str()), r.frame);
      ++restored.keyframes;
    } else {
      std::vector<GraphKeyframe> keyframes;
      keyframes.reserve(r.graph.keyframes.size());
      for (const auto& k : r.graph.keyframes) keyframes.push_back(to_graph_keyframe(k, what.c_str()));
      mapper.restore_poses(keyframes);
      restored.last_revision = r.graph.revision;
    }
  }
  if (restored.keyframes > 0) mapper.rebuild_from_scratch();
  return restored;
}

JournalWriter::JournalWriter(std::string path, uint64_t intact_bytes) : path_(std::move(path)) {
  std::error_code ec;
  if (intact_bytes == 0) {
    out_.open(path_, std::ios::binary | std::ios::trunc);
    out_.write(kHeader, static_cast<std::streamsize>(kHeaderSize));
    bytes_ = kHeaderSize;
  } else {
    std::filesystem::resize_file(path_, intact_bytes, ec);  // the damaged tail goes
    if (ec) throw InputError(path_ + ": cannot cut the mapper journal's damaged end: " + ec.message());
    out_.open(path_, std::ios::binary | std::ios::app);
    bytes_ = intact_bytes;
  }
  out_.flush();
  if (!out_) throw InputError(path_ + ": cannot write the mapper journal: " + std::strerror(errno));
}

void JournalWriter::append(char kind, const std::vector<uint8_t>& payload) {
  std::vector<uint8_t> head{static_cast<uint8_t>(kind)};
  put_u32(head, static_cast<uint32_t>(payload.size()));
  std::vector<uint8_t> tail;
  put_u32(tail, crc32(payload.data(), payload.size(), crc32(head.data(), head.size())));
  out_.write(reinterpret_cast<const char*>(head.data()), static_cast<std::streamsize>(head.size()));
  out_.write(reinterpret_cast<const char*>(payload.data()), static_cast<std::streamsize>(payload.size()));
  out_.write(reinterpret_cast<const char*>(tail.data()), static_cast<std::streamsize>(tail.size()));
  out_.flush();  // to the kernel: a killed process loses nothing written before
  if (!out_) throw std::runtime_error(path_ + ": writing the mapper journal failed: " + std::strerror(errno));
  bytes_ += head.size() + payload.size() + tail.size();
}

void JournalWriter::keyframe(const kestrel::slam_keyframe_t& keyframe, const RgbdFrame& frame) {
  const std::vector<uint8_t> k = transport::encode_message(keyframe);
  const std::vector<uint8_t> f = transport::encode_message(transport::encode_rgbd(frame, lossless()));
  std::vector<uint8_t> payload;
  payload.reserve(4 + k.size() + f.size());
  put_u32(payload, static_cast<uint32_t>(k.size()));
  payload.insert(payload.end(), k.begin(), k.end());
  payload.insert(payload.end(), f.begin(), f.end());
  append(kKeyframe, payload);
}

void JournalWriter::graph(const kestrel::slam_graph_t& graph) {
  append(kGraph, transport::encode_message(graph));
}

void JournalWriter::clear() {
  out_.close();
  out_.open(path_, std::ios::binary | std::ios::trunc);
  out_.write(kHeader, static_cast<std::streamsize>(kHeaderSize));
  out_.flush();
  if (!out_) throw std::runtime_error(path_ + ": cannot write the mapper journal: " + std::strerror(errno));
  bytes_ = kHeaderSize;
}

}  // namespace kestrel::mapper
