#include "mapper/keyframe_journal.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <optional>
#include <utility>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/transport/convert.h"
#include "common/transport/message.h"
#include "common/transport/rgbd_codec.h"
#include "mapper/journal_records.h"

namespace kestrel::mapper {

namespace {

// The journal keeps the frame exactly: raw colour, lossless depth.
transport::RgbdEncoding lossless() {
  transport::RgbdEncoding e;
  e.rgb = kestrel::rgbd_frame_t::RGB_RGB8;
  e.depth = kestrel::rgbd_frame_t::DEPTH_U16_MM_ZSTD;
  return e;
}

}  // namespace

JournalContents read_journal(const std::string& path) {
  JournalContents contents;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec) || std::filesystem::file_size(path, ec) == 0) return contents;
  const journal::JournalBytes file(path);
  contents.file_bytes = file.size();
  std::string header(journal::kHeaderSize, '\0');
  uint64_t at = 0;
  const bool header_ok = file.read(0, header.data(), journal::kHeaderSize) && header == journal::kHeader;
  if (header_ok) {
    at = journal::kHeaderSize;
  } else {
    // Either not a journal at all, or one whose first bytes were damaged: only an intact
    // record after them tells the two apart.
    const std::optional<uint64_t> next = journal::next_record(file, 0, path);
    if (!next) {
      throw InputError(path + ": not a kestrel mapper journal (its first line is not \"" +
                       std::string(journal::kHeader, journal::kHeaderSize - 1) + "\" and no intact record follows)");
    }
    contents.damage = "its header is damaged (at byte 0)";
    contents.skipped_bytes = *next;
    contents.damaged_stretches = 1;
    at = *next;
  }
  while (at < file.size()) {
    const size_t index = contents.records.size();
    std::string why;
    const std::string what = path + ": record " + std::to_string(index);
    if (const uint64_t end = journal::record_at(file, at, what, contents.records, why)) {
      if (!contents.spans.empty() && contents.spans.back().second == at) {
        contents.spans.back().second = end;
      } else {
        contents.spans.emplace_back(at, end);
      }
      at = end;
      continue;
    }
    // Damage: reading goes on at the next intact record (the header says why that is sound).
    if (contents.damage.empty())
      contents.damage = "record " + std::to_string(index) + " " + why + " (at byte " + std::to_string(at) + ")";
    ++contents.damaged_stretches;
    const std::optional<uint64_t> next = journal::next_record(file, at + 1, path);
    contents.skipped_bytes += (next ? *next : file.size()) - at;
    if (!next) break;
    at = *next;
  }
  contents.intact_bytes = header_ok ? journal::kHeaderSize : 0;
  for (const auto& span : contents.spans) contents.intact_bytes += span.second - span.first;
  if (!contents.damage.empty()) {
    contents.damage += "; " + std::to_string(contents.skipped_bytes) + " of " + std::to_string(file.size()) +
                       " bytes unreadable in " + std::to_string(contents.damaged_stretches) + " stretch" +
                       (contents.damaged_stretches == 1 ? "" : "es") + ", " +
                       std::to_string(contents.records.size()) + " intact records kept";
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

JournalWriter::JournalWriter(std::string path, const JournalContents& contents) : path_(std::move(path)) {
  std::error_code ec;
  const bool exists = std::filesystem::exists(path_, ec);
  const uintmax_t size = exists ? std::filesystem::file_size(path_, ec) : 0;
  // What was read must still be what is there: a journal is never written over unread.
  if (ec || size != contents.file_bytes) {
    throw InputError(path_ + ": the mapper journal is not as it was read (" + std::to_string(size) + " bytes, read " +
                     std::to_string(contents.file_bytes) + ")");
  }
  if (contents.file_bytes == 0) {
    start_fresh("", {});
  } else if (!contents.damage.empty()) {
    // Kept whole under a new name first; then `path_` becomes a valid journal of the records
    // read, copied byte for byte, so the damage is neither cut off nor appended after.
    kept_aside_ = keep_aside(path_, "damaged");
    start_fresh(kept_aside_, contents.spans);
  }
  open_for_append();
}

void JournalWriter::start_fresh(const std::string& source, const std::vector<std::pair<uint64_t, uint64_t>>& spans) {
  AtomicFile file(path_);
  file.stream().write(journal::kHeader, static_cast<std::streamsize>(journal::kHeaderSize));
  if (!spans.empty()) {
    const journal::JournalBytes from(source);
    std::vector<char> buffer(1u << 20);
    for (const auto& [begin, end] : spans) {
      for (uint64_t at = begin; at < end;) {
        const size_t n = static_cast<size_t>(std::min<uint64_t>(buffer.size(), end - at));
        if (!from.read(at, buffer.data(), n)) throw InputError(source + ": cannot read the mapper journal back");
        file.stream().write(buffer.data(), static_cast<std::streamsize>(n));
        at += n;
      }
    }
  }
  file.commit();
}

void JournalWriter::open_for_append() {
  out_.open(path_, std::ios::binary | std::ios::app);
  if (!out_) throw InputError(path_ + ": cannot write the mapper journal: " + std::strerror(errno));
  std::error_code ec;
  bytes_ = std::filesystem::file_size(path_, ec);
}

void JournalWriter::append(char kind, const std::vector<uint8_t>& payload) {
  std::vector<uint8_t> head{static_cast<uint8_t>(kind)};
  journal::put_u32(head, static_cast<uint32_t>(payload.size()));
  std::vector<uint8_t> tail;
  journal::put_u32(tail, journal::crc32(payload.data(), payload.size(), journal::crc32(head.data(), head.size())));
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
  journal::put_u32(payload, static_cast<uint32_t>(k.size()));
  payload.insert(payload.end(), k.begin(), k.end());
  payload.insert(payload.end(), f.begin(), f.end());
  append(journal::kKeyframe, payload);
}

void JournalWriter::graph(const kestrel::slam_graph_t& graph) {
  append(journal::kGraph, transport::encode_message(graph));
}

void JournalWriter::restart() {
  kept_aside_.clear();
  if (bytes_ <= journal::kHeaderSize) return;  // no record: nothing to keep
  out_.close();
  // keep_aside throws before anything changed; start_fresh replaces the file by a rename.
  kept_aside_ = keep_aside(path_, "reset");
  start_fresh("", {});
  open_for_append();
}

}  // namespace kestrel::mapper
