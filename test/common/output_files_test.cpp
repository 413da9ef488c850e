// "No file is ever destroyed in place" (issue 38): a file a tool writes whole goes through
// AtomicFile (common/atomic_file.h), so a run that fails or is killed never leaves a cut file
// that looks whole, nor damages the one it was replacing. This test finds every other way of
// opening a file for writing in the sources of the targets the build declares (the layering
// manifest, as layering_test reads it) and fails on any file not listed in kStreams, each with
// the reason its writes are a stream: appended as the data comes, read up to a cut by its
// readers, never rewritten in place.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace kestrel::test {
namespace {

namespace fs = std::filesystem;

const std::map<std::string, std::string> kStreams = {
    {"common/atomic_file.h", "the atomic writer itself"},
    {"common/atomic_file.cpp", "the atomic writer itself"},
    {"common/transport/log_file.cpp",
     "an LCM log, events appended as they come; readers stop at a cut event and say so"},
    {"mapper/keyframe_journal.h", "the mapper's journal, appended record by record (compaction is atomic)"},
    {"drivers/kinect/fakenect_dump.cpp", "a recording: frames and the index line written as they arrive"},
    {"drivers/sim/tum_writer.h", "the simulator's TUM export, a recording written frame by frame"},
    {"drivers/sim/tum_writer.cpp", "the simulator's TUM export, a recording written frame by frame"},
    {"tools/launch/supervisor.cpp", "each process's log, appended"},
    {"tools/launch/isolation.cpp", "the kernel's /proc/self uid and gid maps, not a file of data"},
    {"tools/link/split_flight.cpp", "the scripts of its own flight, in the fresh folder it has just made"},
    {"fuzz/registry.cpp", "inputs for the code under test, in a scratch folder of its own"},
};

struct InPlaceWriter {
  std::string file;
  int line = 0;
  std::string what;
};

// The writes of `text` (a source file) that open a file for writing other than through
// AtomicFile. Comments are skipped: a line's text from "//" on, and lines inside /* */.
std::vector<InPlaceWriter> find_in_place_writers(const std::string& file, const std::string& text) {
  static const std::vector<std::pair<std::regex, std::string>> kPatterns = {
      {std::regex(R"(std::ofstream\b)"), "std::ofstream"},
      {std::regex(R"(std::fstream\b)"), "std::fstream"},
      {std::regex(R"(\bfopen\s*\([^;]*"[wa])"), "fopen for writing"},
      {std::regex(R"((^|[^:\w])(::)?open\s*\([^;]*O_(WRONLY|RDWR))"), "open(2) for writing"},
      {std::regex(R"(\bimwrite\s*\()"), "cv::imwrite"},
  };
  std::vector<InPlaceWriter> found;
  std::istringstream in(text);
  std::string line;
  bool in_block_comment = false;
  for (int number = 1; std::getline(in, line); ++number) {
    if (in_block_comment) {
      const size_t end = line.find("*/");
      if (end == std::string::npos) continue;
      line = line.substr(end + 2);
      in_block_comment = false;
    }
    if (const size_t begin = line.find("/*"); begin != std::string::npos && line.find("*/", begin) == std::string::npos) {
      line = line.substr(0, begin);
      in_block_comment = true;
    }
    if (const size_t comment = line.find("//"); comment != std::string::npos) line = line.substr(0, comment);
    for (const auto& [pattern, what] : kPatterns)
      if (std::regex_search(line, pattern)) found.push_back({file, number, what});
  }
  return found;
}

std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(OutputFiles, EveryFileWrittenWholeGoesThroughAtomicFile) {
  const fs::path manifest = fs::path(KESTREL_BINARY_DIR) / "layering.json";
  std::ifstream in(manifest);
  ASSERT_TRUE(in) << manifest << " is missing: the build writes it at configure time";
  std::set<std::string> dirs;
  for (const auto& target : nlohmann::json::parse(in)) dirs.insert(target.at("dir").get<std::string>());
  ASSERT_GE(dirs.size(), 10u) << "the manifest lists too few folders to be this tree's";
  const fs::path root(KESTREL_SOURCE_DIR);
  std::set<std::string> files;
  for (const std::string& dir : dirs)
    for (const auto& entry : fs::recursive_directory_iterator(root / dir)) {
      const std::string ext = entry.path().extension().string();
      if (entry.is_regular_file() && (ext == ".cpp" || ext == ".h" || ext == ".hpp"))
        files.insert(fs::relative(entry.path(), root).generic_string());
    }
  ASSERT_TRUE(files.count("common/atomic_file.cpp")) << "the scan missed the atomic writer";
  std::string violations;
  std::set<std::string> streams_seen;
  for (const std::string& file : files)
    for (const InPlaceWriter& w : find_in_place_writers(file, read_text(root / file))) {
      if (kStreams.count(file)) streams_seen.insert(file);
      else violations += "\n  " + w.file + ":" + std::to_string(w.line) + ": " + w.what;
    }
  EXPECT_TRUE(violations.empty())
      << "files opened for writing in place (write them with AtomicFile, or add the file to kStreams with the "
         "reason it is a stream):"
      << violations;
  // The list stays true: a file that no longer writes in place leaves it.
  for (const auto& [file, why] : kStreams)
    EXPECT_TRUE(streams_seen.count(file)) << file << " is listed as a stream (" << why << ") but writes nothing in place";
}

// The finder itself, on text made by hand: each way of writing is found once, comments and
// reads are not.
TEST(OutputFiles, TheFinderFindsEachWayOfWritingInPlaceAndNothingElse) {
  const std::string text =
      "std::ofstream out(path);\n"                         // 1
      "std::fstream both(path, std::ios::in | std::ios::out);\n"  // 2
      "FILE* f = std::fopen(path.c_str(), \"wb\");\n"      // 3
      "int fd = ::open(p, O_WRONLY | O_CREAT, 0644);\n"    // 4
      "cv::imwrite(path, image);\n"                        // 5
      "FILE* r = std::fopen(path.c_str(), \"rb\");\n"      // a read
      "std::ifstream read(path);\n"                        // a read
      "int fd2 = ::open(p, O_RDONLY);\n"                   // a read
      "AtomicFile file(path);  // not std::ofstream\n"     // a comment
      "/* std::ofstream in a block\n"
      "   comment */ x = 1;\n"
      "s.reopen(O_WRONLY);\n";                             // another name than open
  const std::vector<InPlaceWriter> found = find_in_place_writers("x.cpp", text);
  ASSERT_EQ(found.size(), 5u);
  const std::vector<std::string> expected = {"std::ofstream", "std::fstream", "fopen for writing",
                                             "open(2) for writing", "cv::imwrite"};
  for (size_t i = 0; i < found.size(); ++i) {
    EXPECT_EQ(found[i].line, static_cast<int>(i) + 1);
    EXPECT_EQ(found[i].what, expected[i]);
  }
}

}  // namespace
}  // namespace kestrel::test
