// The mapper's journal (mapper/keyframe_journal.h), as a mapper started on it reads it and
// rebuilds its map: every intact record kept, damage skipped, never a crash.

#include <filesystem>

#include "fuzz/examples.h"
#include "fuzz/groups.h"
#include "mapper/keyframe_journal.h"
#include "mapper/mapper.h"

namespace kestrel::fuzz {
namespace {

bool run_journal(const uint8_t* data, size_t size) {
  return accepted([&] {
    const mapper::JournalContents journal = mapper::read_journal(scratch_file("mapper.journal", data, size));
    if (journal.intact_bytes + journal.skipped_bytes > journal.file_bytes) {
      defect("mapper-journal", "intact and skipped bytes add up to more than the file");
    }
    mapper::Mapper mapper;
    const mapper::Restored restored = mapper::restore_journal(journal, mapper, "mapper.journal");
    if (restored.keyframes + restored.pinned > static_cast<int64_t>(journal.records.size())) {
      defect("mapper-journal", "more keyframes and pinned frames restored than records read");
    }
  });
}

// A journal as a mapper writes it: two keyframes (a wall 1.5 m ahead, seen from two places),
// a graph that moves the first, a third keyframe, then two frames pinned for keyframes SLAM
// has not placed yet, the first of which joins.
std::vector<Bytes> journal_seeds() {
  const PinholeCamera camera = small_camera(32, 24);
  const auto frame = [&](int64_t utime) {
    RgbdFrame f;
    f.utime = f.depth_utime = utime;
    f.camera = camera;
    f.rgb = cv::Mat(24, 32, CV_8UC3, cv::Scalar(90, 120, 150));
    f.depth_mm = cv::Mat(24, 32, CV_16UC1, cv::Scalar(1500));
    f.depth_mm.row(5).setTo(0);
    return f;
  };
  const std::string path = scratch_dir() + "/seed.journal";
  std::filesystem::remove(path);  // a writer appends to the journal it finds
  {
    mapper::JournalWriter journal(path);
    journal.keyframe(keyframe(1000000, 0.0), frame(1000000));
    journal.keyframe(keyframe(2000000, 0.3), frame(2000000));
    kestrel::slam_graph_t moved{};
    moved.utime = 2000000;
    moved.revision = 2;
    moved.keyframes = {keyframe(1000000, 0.02)};
    moved.num_keyframes = 1;
    journal.graph(moved);
    journal.keyframe(keyframe(3000000, 0.6), frame(3000000));
    journal.pinned(frame(4000000));
    journal.pinned(frame(5000000));
    journal.keyframe(keyframe(4000000, 0.9), frame(4000000));
  }
  return {file_bytes(path)};
}

}  // namespace

std::vector<Target> journal_targets() {
  return {{"mapper-journal", "the mapper's keyframe journal, as a restarted mapper restores it", &run_journal, &journal_seeds}};
}

}  // namespace kestrel::fuzz
