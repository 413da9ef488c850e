// "No file is ever destroyed in place" (issue 38): a file a tool writes whole goes through
// AtomicFile (common/atomic_file.h), so a run that fails or is killed never leaves a cut file
// that looks whole, nor damages the one it was replacing. This test finds every other way of
// opening a file for writing in the sources of the targets the build declares (the layering
// manifest, as layering_test reads it) and fails on each that does not say, in a comment
// "in-place: <reason>" on its statement or the line before, why it writes in place: a stream
// (a log, the journal, a recording) appended as the data comes and read up to a cut by its
// readers, or the atomic writer's own temporary.
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <iterator>
#include <regex>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "source_tree.h"

namespace kestrel::test {
namespace {

namespace fs = std::filesystem;

struct InPlaceWriter {
  std::string file;
  int line = 0;  ///< the statement's first line
  std::string what;
  bool marked = false;  ///< it says why it writes in place
};

// `line` without its comments, and with the text of each string literal dropped unless it is
// as short as a file mode ("wb", "r+"): a // or a name inside a string is not code. `in_block`
// says whether a /* comment is open, before the line and after it.
std::string code_of(const std::string& line, bool& in_block) {
  std::string code, literal;
  char quote = 0;
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    const char next = i + 1 < line.size() ? line[i + 1] : '\0';
    if (in_block) {
      if (c == '*' && next == '/') in_block = false, ++i;
      continue;
    }
    if (quote) {
      if (c == '\\' && next) {
        literal += next, ++i;
      } else if (c == quote) {
        code += quote + (literal.size() <= 3 ? literal : std::string()) + quote;
        quote = 0;
      } else {
        literal += c;
      }
      continue;
    }
    if (c == '/' && next == '/') break;
    if (c == '/' && next == '*') {
      in_block = true, ++i;
      continue;
    }
    if (c == '"' || c == '\'') {
      quote = c;
      literal.clear();
      continue;
    }
    code += c;
  }
  return code;
}

// What the statement `code` opens for writing, or "" if nothing.
std::string writes_in(const std::string& code) {
  // Every pattern below holds one of these words. Most statements hold none, and std::regex
  // is slow (15 s for the tree under the sanitizers' -O0 without this test).
  static const char* const kWords[] = {"fstream", "open", "creat", "copy_file", "imwrite", "bagmode"};
  if (std::none_of(std::begin(kWords), std::end(kWords),
                   [&](const char* w) { return code.find(w) != std::string::npos; }))
    return "";
  static const std::regex include(R"(^\s*#\s*include\b)");
  if (std::regex_search(code, include)) return "";
  static const std::vector<std::pair<std::regex, std::string>> kWays = {
      {std::regex(R"(ofstream\b)"), "an ofstream"},
      {std::regex(R"(\bfstream\b)"), "an fstream"},
      {std::regex(R"(\bfdopen\s*\()"), "fdopen"},
      {std::regex(R"(\b(open|openat)\s*\([^;]*\bO_(WRONLY|RDWR)\b)"), "open(2) for writing"},
      {std::regex(R"(\bcreat\s*\()"), "creat(2)"},
      {std::regex(R"(\.open\s*\([^;]*\bios(_base)?::(out|app|trunc)\b)"), "a stream opened for writing"},
      {std::regex(R"(\bcopy_file\s*\()"), "copy_file"},
      {std::regex(R"(\bimwrite\s*\()"), "imwrite"},
      {std::regex(R"(bagmode::Write\b)"), "a bag opened for writing"},
  };
  for (const auto& [pattern, what] : kWays)
    if (std::regex_search(code, pattern)) return what;
  // fopen and freopen unless their mode is spelled out and only reads.
  static const std::regex fopen(R"(\bf(re)?open\s*\()"), reads(R"("rb?")");
  if (std::regex_search(code, fopen) && !std::regex_search(code, reads)) return "fopen for writing";
  return "";
}

// The statements of `text` (a source file) that open a file for writing other than through
// AtomicFile, each marked or not. A statement runs to the line holding ';', '{' or '}'.
std::vector<InPlaceWriter> find_in_place_writers(const std::string& file, const std::string& text) {
  std::vector<InPlaceWriter> found;
  std::istringstream in(text);
  std::string line, statement;
  // A marker on a line of its own marks the statement after it; one after a statement's code
  // marks that statement only.
  bool in_block = false, marked = false, marker_line_before = false;
  int first = 0;
  for (int number = 1; std::getline(in, line); ++number) {
    const std::string code = code_of(line, in_block);
    if (statement.empty()) {
      first = number;
      marked = marker_line_before;
    }
    statement += code + "\n";
    const bool marker = line.find("in-place:") != std::string::npos;
    marked = marked || marker;
    marker_line_before = marker && code.find_first_not_of(" \t") == std::string::npos;
    if (code.find_first_of(";{}") == std::string::npos && !code.empty() && code.find('#') == std::string::npos) continue;
    if (const std::string what = writes_in(statement); !what.empty()) found.push_back({file, first, what, marked});
    statement.clear();
  }
  if (const std::string what = writes_in(statement); !what.empty()) found.push_back({file, first, what, marked});
  return found;
}

TEST(OutputFiles, EveryFileWrittenWholeGoesThroughAtomicFile) {
  const std::optional<nlohmann::json> manifest = read_layering_manifest();
  ASSERT_TRUE(manifest) << "layering.json is missing: the build writes it at configure time";
  std::set<std::string> dirs;
  for (const auto& target : *manifest) dirs.insert(target.at("dir").get<std::string>());
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
  std::string unmarked;
  int marked = 0;
  for (const std::string& file : files)
    for (const InPlaceWriter& w : find_in_place_writers(file, read_source(file).value_or(std::string()))) {
      if (w.marked) ++marked;
      else unmarked += "\n  " + w.file + ":" + std::to_string(w.line) + ": " + w.what;
    }
  EXPECT_TRUE(unmarked.empty()) << "files opened for writing in place (write them with AtomicFile, or say why on the "
                                   "statement with a comment \"in-place: <reason>\"):"
                                << unmarked;
  // The streams are there, and found: the scan sees what it should.
  EXPECT_GE(marked, 8) << "the marked writers (the LCM log, the journal, the recordings, the atomic writer's own "
                          "temporary) were not all found";
}

// The finder itself, on text made by hand: each way of writing is found once, with its
// statement's first line, marked or not; comments, strings and reads are not.
TEST(OutputFiles, TheFinderFindsEachWayOfWritingInPlaceAndNothingElse) {
  const std::string text =
      "std::ofstream out(path);\n"                                      // 1
      "std::fstream both(path);\n"                                      // 2
      "FILE* f = std::fopen(path.c_str(), \"wb\");\n"                   // 3
      "int fd = ::open(p, O_WRONLY | O_CREAT, 0644);\n"                 // 4
      "cv::imwrite(path, image);\n"                                     // 5
      "FILE* g = std::fopen(path.c_str(),\n"                            // 6: over two lines
      "                     \"r+\");\n"
      "FILE* h = fopen(name, mode);\n"                                  // 8: a mode not spelled out
      "journal.open(path, std::ios::binary | std::ios::app);\n"         // 9
      "fs::copy_file(a, b, fs::copy_options::overwrite_existing);\n"    // 10
      "ofstream bare(path);\n"                                          // 11
      "// in-place: a log, appended\n"
      "FILE* log = std::fopen(path.c_str(), \"a\");\n"                  // 13, marked on the line before
      "int fd2 = creat(p, 0644);  // in-place: a lock file\n"           // 14, marked on its line
      "FILE* d = fdopen(fd, \"w\");\n"                                   // 15
      "bag.open(path, rosbag::bagmode::Write);\n"                       // 16
      "FILE* e = std::freopen(path.c_str(), \"w\", stdout);\n"          // 17
      "FILE* r = std::fopen(path.c_str(), \"rb\");\n"                   // reads
      "std::ifstream read(path);\n"
      "int fd3 = ::open(p, O_RDONLY);\n"
      "AtomicFile file(path);  // not std::ofstream\n"                  // a comment
      "/* std::ofstream in a block\n"
      "   comment */ x = 1;\n"
      "url = \"file://\"; std::string s = \"std::ofstream\";\n"           // strings... and a // in one
      "#include <fstream>\n";
  const std::vector<InPlaceWriter> found = find_in_place_writers("x.cpp", text);
  const std::vector<std::pair<int, bool>> expected = {{1, false}, {2, false},  {3, false},  {4, false},
                                                      {5, false}, {6, false},  {8, false},  {9, false},
                                                      {10, false}, {11, false}, {13, true}, {14, true},
                                                      {15, false}, {16, false}, {17, false}};
  ASSERT_EQ(found.size(), expected.size());
  for (size_t i = 0; i < found.size(); ++i) {
    EXPECT_EQ(found[i].line, expected[i].first) << found[i].what;
    EXPECT_EQ(found[i].marked, expected[i].second) << "line " << found[i].line;
  }
}

}  // namespace
}  // namespace kestrel::test
