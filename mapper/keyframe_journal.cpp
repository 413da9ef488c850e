#include "mapper/keyframe_journal.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <optional>
#include <stdexcept>
#include <string_view>
#include <utility>

#include "common/atomic_file.h"
#include "common/error.h"
#include "common/transport/convert.h"
#include "common/transport/message.h"
#include "common/transport/rgbd_codec.h"
#include "mapper/journal_records.h"

namespace kestrel::mapper {

namespace {

namespace fs = std::filesystem;

// The journal keeps the frame exactly: raw colour, lossless depth.
transport::RgbdEncoding lossless() {
  transport::RgbdEncoding e;
  e.rgb = kestrel::rgbd_frame_t::RGB_RGB8;
  e.depth = kestrel::rgbd_frame_t::DEPTH_U16_MM_ZSTD;
  return e;
}

// A whole number of at most 18 digits (no sign, no spaces), or empty.
std::optional<int64_t> whole_number(std::string_view digits) {
  if (digits.empty() || digits.size() > 18) return std::nullopt;
  int64_t value = 0;
  for (const char c : digits) {
    if (c < '0' || c > '9') return std::nullopt;
    value = value * 10 + (c - '0');
  }
  return value;
}

// What follows "<path>.<tag>-" in a name keep_aside() gives, "<utime>" or "<utime>-<n>" (n >= 2,
// a second name in one microsecond), as (utime, n) with n = 1 for the first; else empty, and
// the file is not one the writer kept.
std::optional<std::pair<int64_t, int64_t>> kept_order(std::string_view suffix) {
  const size_t dash = suffix.find('-');
  const std::optional<int64_t> utime = whole_number(suffix.substr(0, dash));
  if (!utime) return std::nullopt;
  if (dash == std::string_view::npos) return std::make_pair(*utime, int64_t{1});
  const std::optional<int64_t> n = whole_number(suffix.substr(dash + 1));
  if (!n || *n < 2) return std::nullopt;
  return std::make_pair(*utime, *n);
}

}  // namespace

std::vector<std::string> kept_journals(const std::string& path, const std::string& tag) {
  const fs::path journal(path);
  const fs::path folder = journal.parent_path().empty() ? fs::path(".") : journal.parent_path();
  const std::string prefix = journal.filename().string() + "." + tag + "-";
  std::vector<std::pair<std::pair<int64_t, int64_t>, std::string>> found;
  std::error_code ec;
  for (fs::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const auto order = kept_order(std::string_view(name).substr(prefix.size()));
    // keep_aside() makes regular files (a hard link or a copy); anything else is not ours.
    std::error_code type_ec;
    if (!order || it->symlink_status(type_ec).type() != fs::file_type::regular) continue;
    found.emplace_back(*order, (journal.parent_path() / name).string());
  }
  if (ec) throw InputError(folder.string() + ": cannot list the journals kept aside: " + ec.message());
  std::sort(found.begin(), found.end());
  std::vector<std::string> names;
  names.reserve(found.size());
  for (auto& entry : found) names.push_back(std::move(entry.second));
  return names;
}

PrunedJournals prune_kept_journals(const std::string& path, const std::string& tag, int keep,
                                   const std::string& just_kept) {
  if (keep < 1)
    throw std::invalid_argument("pruning the kept journals: keep must be >= 1, not " + std::to_string(keep));
  PrunedJournals pruned;
  std::vector<std::string> kept;
  try {
    kept = kept_journals(path, tag);
  } catch (const InputError& e) {
    pruned.failures.push_back(e.what());
    return pruned;
  }
  const fs::path newest = fs::path(just_kept).filename();
  const auto is_newest = [&](const std::string& p) { return !just_kept.empty() && fs::path(p).filename() == newest; };
  const size_t before = kept.size();
  kept.erase(std::remove_if(kept.begin(), kept.end(), is_newest), kept.end());
  const size_t others_kept = static_cast<size_t>(keep) - (kept.size() < before ? 1 : 0);
  for (size_t i = 0; i + others_kept < kept.size(); ++i) {  // oldest first
    std::error_code ec;
    if (fs::remove(kept[i], ec)) {
      pruned.removed.push_back(kept[i]);
    } else if (ec) {
      pruned.failures.push_back(kept[i] + ": cannot delete it: " + ec.message());
    }
  }
  return pruned;
}

JournalContents read_journal(const std::string& path) {
  JournalContents contents;
  std::error_code ec;
  if (!std::filesystem::exists(path, ec) || std::filesystem::file_size(path, ec) == 0) return contents;
  const journal::JournalBytes file(path);
  contents.file_bytes = file.size();
  std::string header(journal::kHeaderSize, '\0');
  uint64_t at = 0;
  const bool header_read = file.read(0, header.data(), journal::kHeaderSize);
  const bool header_ok = header_read && (header == journal::kHeader || header == journal::kHeaderVersion1);
  if (header_ok) contents.version = header == journal::kHeader ? 2 : 1;
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
  // Pinned frames by utime, oldest first; a keyframe record of the same time after a pin is
  // its keyframe joining (Mapper::apply_graph took the pinned frame then).
  std::map<int64_t, const RgbdFrame*> pinned;
  for (const JournalRecord& r : journal.records) {
    if (r.kind == JournalRecord::Kind::kPinned) {
      pinned[r.frame.utime] = &r.frame;
    } else if (r.kind == JournalRecord::Kind::kReleased) {
      for (const auto& k : r.graph.keyframes) pinned.erase(k.utime);
    } else if (r.kind == JournalRecord::Kind::kKeyframe) {
      mapper.restore_keyframe(to_graph_keyframe(r.keyframe, what.c_str()), r.frame);
      pinned.erase(r.keyframe.utime);
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
  const size_t pinned_before = mapper.pinned();
  for (const auto& [utime, frame] : pinned) mapper.restore_pinned(*frame);  // the oldest go past the bound
  restored.pinned = static_cast<int64_t>(mapper.pinned() - pinned_before);
  return restored;
}

JournalWriter::JournalWriter(std::string path, const JournalContents& contents, int keep)
    : path_(std::move(path)), keep_(keep) {
  if (keep_ < 1)
    throw std::invalid_argument(path_ + ": journals kept aside: keep must be >= 1, not " + std::to_string(keep_));
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
  } else if (contents.damage.empty() && contents.version == 1) {
    // Continued as version 2 (its records copied byte for byte under the new header), so that
    // no version 2 record lands under a header that does not announce it.
    start_fresh(path_, contents.spans);
  } else if (!contents.damage.empty()) {
    // Kept whole under a new name first; then `path_` becomes a valid journal of the records
    // read, copied byte for byte, so the damage is neither cut off nor appended after.
    kept_aside_ = keep_aside(path_, "damaged");
    start_fresh(kept_aside_, contents.spans);
    // Only once the fresh journal is in place: until then the damaged file is the only copy.
    pruned_ = prune_kept_journals(path_, "damaged", keep_, kept_aside_);
  }
  open_for_append();
  for (const JournalRecord& r : contents.records) {
    if (r.kind == JournalRecord::Kind::kKeyframe) {
      place(r.keyframe);
    } else if (r.kind == JournalRecord::Kind::kGraph) {
      for (const auto& k : r.graph.keyframes) place(k);
    }
  }
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
  // in-place: the journal, appended record by record (compaction is atomic)
  out_.open(path_, std::ios::binary | std::ios::app);
  if (!out_) throw InputError(path_ + ": cannot write the mapper journal: " + std::strerror(errno));
  std::error_code ec;
  bytes_ = std::filesystem::file_size(path_, ec);
}

uint64_t JournalWriter::write_record(std::ostream& out, char kind, const std::vector<uint8_t>& payload) {
  // A reader takes a larger size field for damage: such a record would be lost on reading.
  if (payload.size() > journal::kMaxPayload)
    throw std::runtime_error("a mapper journal record of " + std::to_string(payload.size()) + " bytes (at most " +
                             std::to_string(journal::kMaxPayload) + ")");
  std::vector<uint8_t> bytes{static_cast<uint8_t>(kind)};
  journal::put_u32(bytes, static_cast<uint32_t>(payload.size()));
  const uint32_t crc = journal::crc32(payload.data(), payload.size(), journal::crc32(bytes.data(), bytes.size()));
  bytes.reserve(bytes.size() + payload.size() + 4);
  bytes.insert(bytes.end(), payload.begin(), payload.end());
  journal::put_u32(bytes, crc);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  return bytes.size();
}

std::vector<uint8_t> JournalWriter::frame_payload(const RgbdFrame& frame) {
  return transport::encode_message(transport::encode_rgbd(frame, lossless()));
}

std::vector<uint8_t> JournalWriter::keyframe_payload(const kestrel::slam_keyframe_t& keyframe, const RgbdFrame& frame) {
  const std::vector<uint8_t> k = transport::encode_message(keyframe);
  const std::vector<uint8_t> f = frame_payload(frame);
  std::vector<uint8_t> payload;
  payload.reserve(4 + k.size() + f.size());
  journal::put_u32(payload, static_cast<uint32_t>(k.size()));
  payload.insert(payload.end(), k.begin(), k.end());
  payload.insert(payload.end(), f.begin(), f.end());
  return payload;
}

void JournalWriter::append(char kind, const std::vector<uint8_t>& payload) {
  const uint64_t written = write_record(out_, kind, payload);
  out_.flush();  // to the kernel: a killed process loses nothing written before
  if (!out_) throw std::runtime_error(path_ + ": writing the mapper journal failed: " + std::strerror(errno));
  bytes_ += written;
}

void JournalWriter::keyframe(const kestrel::slam_keyframe_t& keyframe, const RgbdFrame& frame) {
  append(journal::kKeyframe, keyframe_payload(keyframe, frame));
  place(keyframe);
}

void JournalWriter::graph(const kestrel::slam_graph_t& graph) {
  append(journal::kGraph, transport::encode_message(graph));
  for (const auto& k : graph.keyframes) place(k);
}

void JournalWriter::pinned(const RgbdFrame& frame) { append(journal::kPinned, frame_payload(frame)); }

void JournalWriter::released(const std::vector<int64_t>& utimes) {
  kestrel::slam_graph_t message{};
  for (const int64_t utime : utimes) {
    kestrel::slam_keyframe_t k{};
    k.utime = utime;
    message.keyframes.push_back(k);
  }
  message.num_keyframes = static_cast<int32_t>(message.keyframes.size());
  append(journal::kReleased, transport::encode_message(message));
}

void JournalWriter::compact(const std::vector<LiveKeyframe>& keyframes, int64_t graph_revision,
                            const std::vector<const RgbdFrame*>& pinned) {
  {
    AtomicFile file(path_);  // the old journal stays whole (and open for append) until commit
    file.stream().write(journal::kHeader, static_cast<std::streamsize>(journal::kHeaderSize));
    for (const LiveKeyframe& k : keyframes) {
      const auto placed = placed_.find(k.id);
      if (placed == placed_.end() || k.frame == nullptr)
        throw std::invalid_argument(path_ + ": compacting: keyframe " + std::to_string(k.id) +
                                    (k.frame == nullptr ? " has no frame" : " was never in this journal"));
      write_record(file.stream(), journal::kKeyframe, keyframe_payload(placed->second, *k.frame));
    }
    if (graph_revision >= 0) {
      kestrel::slam_graph_t graph{};
      graph.revision = graph_revision;
      write_record(file.stream(), journal::kGraph, transport::encode_message(graph));
    }
    for (const RgbdFrame* frame : pinned) write_record(file.stream(), journal::kPinned, frame_payload(*frame));
    file.commit();
  }
  out_.close();
  open_for_append();
  ++compactions_;
  std::map<int64_t, kestrel::slam_keyframe_t> live;  // the others are gone with the old file
  for (const LiveKeyframe& k : keyframes) live.insert(placed_.extract(k.id));
  placed_ = std::move(live);
}

void JournalWriter::restart() {
  kept_aside_.clear();
  pruned_ = {};
  if (bytes_ <= journal::kHeaderSize) return;  // no record: nothing to keep
  out_.close();
  // keep_aside throws before anything changed; start_fresh replaces the file by a rename.
  kept_aside_ = keep_aside(path_, "reset");
  start_fresh("", {});
  open_for_append();
  placed_.clear();
  pruned_ = prune_kept_journals(path_, "reset", keep_, kept_aside_);
}

}  // namespace kestrel::mapper
