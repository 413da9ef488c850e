// The layering rule of docs/architecture.md, checked on the source tree the build describes
// (<build>/layering.json, written by kestrel_write_layering_manifest):
//  1. an ALGORITHM library (no LCM, files or clocks) includes nothing of LCM (`kestrel/...`
//     generated types, <lcm/...>), of tools/, drivers/ or common/transport/;
//  2. every library includes only its own headers and those of the kestrel libraries it links
//     (directly or through them), so that the dependency graph in the CMake files is the
//     real one;
//  3. a library of another component includes only a library's public headers, when it
//     declares them (kestrel_library's PUBLIC_HEADERS): the others are its internals. A
//     component is a top-level folder (vo/, slam/), or one below tools/, drivers/ or common/.
// A header belongs to the target that compiles the .cpp of the same name; a header without
// one belongs to the first library declared in its folder (or the nearest folder above).
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <regex>
#include <iterator>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "source_tree.h"

namespace kestrel::test {
namespace {

namespace fs = std::filesystem;

struct Target {
  std::string name;
  bool tool = false;
  bool algorithm = false;
  std::string dir;                   // relative to the source root
  std::vector<std::string> sources;  // relative to the source root
  std::vector<std::string> links;    // kestrel libraries linked directly
  std::optional<std::set<std::string>> public_headers;  // relative to the root; none: all public
};

std::vector<Target> parse_manifest(const nlohmann::json& j) {
  std::vector<Target> targets;
  for (const auto& e : j) {
    Target t;
    t.name = e.at("name").get<std::string>();
    t.tool = e.at("kind").get<std::string>() == "tool";
    t.algorithm = e.at("algorithm").get<bool>();
    t.dir = e.at("dir").get<std::string>();
    t.sources = e.at("sources").get<std::vector<std::string>>();
    for (const auto& l : e.at("links")) {
      if (l.get<std::string>() != "kestrel_options") t.links.push_back(l.get<std::string>());
    }
    if (e.contains("public") && e.at("public").is_array())
      t.public_headers = e.at("public").get<std::set<std::string>>();
    targets.push_back(std::move(t));
  }
  return targets;
}

std::string without_extension(const std::string& path) {
  return (fs::path(path).parent_path() / fs::path(path).stem()).generic_string();
}

/// The quoted includes of a file's text, in order.
std::vector<std::string> quoted_includes(const std::string& text) {
  static const std::regex include(R"(^\s*#\s*include\s*"([^"]+)\")");
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_search(line, m, include)) out.push_back(m[1]);
  }
  return out;
}

/// The system includes of a file's text (<lcm/...> is what rule 1 looks for).
std::vector<std::string> angle_includes(const std::string& text) {
  static const std::regex include(R"(^\s*#\s*include\s*<([^>]+)>)");
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) {
    std::smatch m;
    if (std::regex_search(line, m, include)) out.push_back(m[1]);
  }
  return out;
}

bool starts_with(const std::string& s, const std::string& prefix) {
  return s.compare(0, prefix.size(), prefix) == 0;
}

/// The component a folder belongs to: its first part ("slam/place" -> "slam"), or its first two
/// below tools/, drivers/ and common/ ("tools/eval", "drivers/sim", "common/transport").
std::string component_of(const std::string& dir) {
  const fs::path p(dir);
  auto it = p.begin();
  if (it == p.end()) return "";
  const std::string first = it->string();
  if ((first == "tools" || first == "drivers" || first == "common") && std::next(it) != p.end())
    return first + "/" + std::next(it)->string();
  return first;
}

/// Every broken rule, one line each: "<file> (<target>): <what>". `read(path)` returns a
/// file's text, or nothing if it does not exist (relative paths from the source root).
std::vector<std::string> layering_violations(
    const std::vector<Target>& targets,
    const std::function<std::optional<std::string>(const std::string&)>& read) {
  std::map<std::string, const Target*> by_name;
  std::map<std::string, std::string> owner_by_stem;  // "vo/lens" -> "kestrel_vo"
  std::map<std::string, std::string> primary_by_dir;
  for (const Target& t : targets) {
    by_name[t.name] = &t;
    for (const std::string& s : t.sources) owner_by_stem[without_extension(s)] = t.name;
    if (!t.tool) primary_by_dir.emplace(t.dir, t.name);  // the first declared wins
  }
  auto owner = [&](const std::string& include) -> std::string {
    if (starts_with(include, "kestrel/")) return "kestrel_lcmtypes";
    if (auto it = owner_by_stem.find(without_extension(include)); it != owner_by_stem.end())
      return it->second;
    for (fs::path d = fs::path(include).parent_path(); !d.empty(); d = d.parent_path()) {
      if (auto it = primary_by_dir.find(d.generic_string()); it != primary_by_dir.end())
        return it->second;
    }
    return "";
  };
  auto reachable = [&](const Target& t) {
    std::set<std::string> seen{t.name};
    std::vector<std::string> todo = t.links;
    while (!todo.empty()) {
      const std::string n = todo.back();
      todo.pop_back();
      if (!seen.insert(n).second) continue;
      if (auto it = by_name.find(n); it != by_name.end())
        todo.insert(todo.end(), it->second->links.begin(), it->second->links.end());
    }
    return seen;
  };

  std::vector<std::string> violations;
  // A declared public header that is not there (renamed, moved) would leave a hole in rule 3.
  for (const Target& t : targets) {
    if (!t.public_headers) continue;
    for (const std::string& h : *t.public_headers)
      if (!read(h)) violations.push_back(h + " (" + t.name + "): declared in PUBLIC_HEADERS but not there");
  }
  for (const Target& t : targets) {
    if (t.tool || starts_with(t.dir, "test")) continue;
    // The library's sources and the headers that belong to it.
    std::set<std::string> files(t.sources.begin(), t.sources.end());
    for (const std::string& s : t.sources) {
      const std::string header = without_extension(s) + ".h";
      if (read(header)) files.insert(header);
    }
    const std::set<std::string> allowed = reachable(t);
    std::set<std::string> checked;
    std::vector<std::string> todo(files.begin(), files.end());
    while (!todo.empty()) {
      const std::string file = todo.back();
      todo.pop_back();
      if (!checked.insert(file).second) continue;
      const std::optional<std::string> text = read(file);
      if (!text) continue;
      for (const std::string& inc : quoted_includes(*text)) {
        const bool in_tree = read(inc).has_value();
        if (!in_tree && !starts_with(inc, "kestrel/")) continue;  // a system or generated header
        if (t.algorithm &&
            (starts_with(inc, "kestrel/") || starts_with(inc, "tools/") ||
             starts_with(inc, "drivers/") || starts_with(inc, "common/transport/"))) {
          violations.push_back(file + " (" + t.name + ", an algorithm library): includes \"" +
                               inc + "\" (LCM, tools, drivers and transport are for processes)");
          continue;
        }
        const std::string o = owner(inc);
        if (o.empty()) continue;
        if (!allowed.count(o)) {
          violations.push_back(file + " (" + t.name + "): includes \"" + inc + "\" of " + o +
                               ", which " + t.name + " does not link");
          continue;
        }
        if (o != t.name && in_tree) {
          const Target& owner_target = *by_name.at(o);
          if (owner_target.public_headers && !owner_target.public_headers->count(inc) &&
              component_of(owner_target.dir) != component_of(t.dir)) {
            violations.push_back(file + " (" + t.name + "): includes \"" + inc + "\", an internal header of " +
                                 o + " (not among its PUBLIC_HEADERS)");
            continue;
          }
        }
        // A header of its own library: its includes are the library's too.
        if (o == t.name && in_tree) todo.push_back(inc);
      }
      if (t.algorithm) {
        for (const std::string& inc : angle_includes(*text)) {
          if (starts_with(inc, "lcm/"))
            violations.push_back(file + " (" + t.name + ", an algorithm library): includes <" +
                                 inc + ">");
        }
      }
    }
  }
  return violations;
}

TEST(Layering, EveryLibraryIncludesOnlyWhatItLinksAndAlgorithmsNoLcmToolsOrDrivers) {
  const std::optional<nlohmann::json> manifest = read_layering_manifest();
  ASSERT_TRUE(manifest) << "layering.json is missing: the build writes it at configure time";
  const std::vector<Target> targets = parse_manifest(*manifest);
  ASSERT_GE(targets.size(), 20u) << "the manifest lists too few targets to be this tree's";
  // The rule has something to bite on: the algorithm libraries are declared as such.
  for (const char* name : {"kestrel_common", "kestrel_vo", "kestrel_estimator", "kestrel_slam",
                           "kestrel_mapper", "kestrel_planner", "kestrel_control"}) {
    const auto it = std::find_if(targets.begin(), targets.end(),
                                 [&](const Target& t) { return t.name == name; });
    ASSERT_NE(it, targets.end()) << name;
    EXPECT_TRUE(it->algorithm) << name << " is not declared ALGORITHM";
  }
  const std::vector<std::string> violations = layering_violations(targets, read_source);
  std::string listing;
  for (const std::string& v : violations) listing += "\n  " + v;
  EXPECT_TRUE(violations.empty()) << violations.size() << " layering violations:" << listing;
}

// The checker itself, on a tree made by hand: each rule is broken once and found.
TEST(Layering, TheCheckerFindsEachKindOfViolationInAHandMadeTree) {
  const std::map<std::string, std::string> files = {
      {"algo/a.cpp", "#include \"algo/a.h\"\n#include \"other/b.h\"\n"},
      {"algo/a.h", "#pragma once\n#include \"kestrel/state_t.hpp\"\n#include <lcm/lcm-cpp.hpp>\n"},
      {"other/b.h", "#pragma once\n"},
      {"other/b.cpp", "#include \"other/b.h\"\n#include \"tools/eval/x.h\"\n"},
      {"tools/eval/x.h", "#pragma once\n"},
      {"tools/eval/x.cpp", "#include \"tools/eval/x.h\"\n"},
      // A component with public headers: its own folder may use its internals, another may not.
      {"pub/api.h", "#pragma once\n"},
      {"pub/api.cpp", "#include \"pub/api.h\"\n#include \"pub/detail.h\"\n"},
      {"pub/detail.h", "#pragma once\n"},
      {"pub/detail.cpp", "#include \"pub/detail.h\"\n"},
      {"pub/io/io.cpp", "#include \"pub/detail.h\"\n"},
      {"user/u.cpp", "#include \"pub/api.h\"\n#include \"pub/detail.h\"\n"},
  };
  auto read = [&](const std::string& p) -> std::optional<std::string> {
    const auto it = files.find(p);
    if (it == files.end()) return std::nullopt;
    return it->second;
  };
  std::vector<Target> targets = {
      {"lib_algo", false, true, "algo", {"algo/a.cpp"}, {}, std::nullopt},
      {"lib_other", false, false, "other", {"other/b.cpp"}, {}, std::nullopt},
      {"lib_eval", false, false, "tools/eval", {"tools/eval/x.cpp"}, {}, std::nullopt},
      {"lib_pub", false, false, "pub", {"pub/api.cpp", "pub/detail.cpp"}, {},
       std::set<std::string>{"pub/api.h", "pub/gone.h"}},
      {"lib_pub_io", false, false, "pub/io", {"pub/io/io.cpp"}, {"lib_pub"}, std::nullopt},
      {"lib_user", false, false, "user", {"user/u.cpp"}, {"lib_pub"}, std::nullopt},
  };
  const std::vector<std::string> v = layering_violations(targets, read);
  auto found = [&](const std::string& part) {
    return std::any_of(v.begin(), v.end(),
                       [&](const std::string& s) { return s.find(part) != std::string::npos; });
  };
  EXPECT_TRUE(found("algo/a.cpp (lib_algo): includes \"other/b.h\" of lib_other")) << v.size();
  EXPECT_TRUE(found("algo/a.h (lib_algo, an algorithm library): includes \"kestrel/state_t.hpp\""));
  EXPECT_TRUE(found("algo/a.h (lib_algo, an algorithm library): includes <lcm/lcm-cpp.hpp>"));
  EXPECT_TRUE(found("other/b.cpp (lib_other): includes \"tools/eval/x.h\" of lib_eval"));
  EXPECT_TRUE(found("user/u.cpp (lib_user): includes \"pub/detail.h\", an internal header of lib_pub"));
  EXPECT_FALSE(found("pub/io/io.cpp")) << "the component's own libraries may include its internals";
  EXPECT_TRUE(found("pub/gone.h (lib_pub): declared in PUBLIC_HEADERS but not there"));
  EXPECT_EQ(v.size(), 6u);

  // Linking what it includes mends the non-algorithm library; the algorithm one stays wrong
  // for LCM whatever it links.
  targets[0].links = {"lib_other"};
  targets[1].links = {"lib_eval"};
  targets[3].public_headers = std::set<std::string>{"pub/api.h", "pub/detail.h"};  // public now; gone.h gone
  const std::vector<std::string> mended = layering_violations(targets, read);
  EXPECT_EQ(mended.size(), 2u);
}

}  // namespace
}  // namespace kestrel::test
