#include "tools/launch/process_set.h"

#include <unistd.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <set>
#include <sstream>

#include "common/error.h"

namespace kestrel::launch {
namespace {

std::string where(const std::filesystem::path& file, const YAML::Node& node) {
  const auto mark = node.Mark();
  return mark.is_null() ? file.string() : file.string() + ":" + std::to_string(mark.line + 1);
}

ProcessSpec read_process(const std::filesystem::path& file, const YAML::Node& node) {
  if (!node.IsMap())
    throw InputError(where(file, node) + ": a process is a map (name, command, side, restart_args)");
  for (const auto& key : node) {
    const auto k = key.first.as<std::string>();
    if (k != "name" && k != "command" && k != "side" && k != "restart_args")
      throw InputError(where(file, key.first) + ": unknown key '" + k + "' (name, command, side, restart_args)");
  }
  ProcessSpec p;
  if (!node["name"] || !node["command"] || !node["side"])
    throw InputError(where(file, node) + ": a process needs name, command and side");
  p.name = node["name"].as<std::string>();
  p.argv = split_command(node["command"].as<std::string>());
  p.side = node["side"].as<std::string>();
  if (node["restart_args"]) p.restart_args = split_command(node["restart_args"].as<std::string>());
  if (p.name.empty() || p.name.find_first_of(" /\t") != std::string::npos)
    throw InputError(where(file, node["name"]) + ": a name is one word without '/'");
  if (p.argv.empty()) throw InputError(where(file, node["command"]) + ": empty command");
  if (p.side != "onboard" && p.side != "offboard")
    throw InputError(where(file, node["side"]) + ": side is onboard or offboard, not '" + p.side + "'");
  return p;
}

}  // namespace

std::vector<std::string> split_command(const std::string& command) {
  std::istringstream in(command);
  std::vector<std::string> words;
  for (std::string w; in >> w;) words.push_back(w);
  return words;
}

namespace {
const std::string kRunDirKey = "{run_dir}";
}  // namespace

std::vector<std::string> command_of_start(const ProcessSpec& process, int run) {
  std::vector<std::string> args = process.argv;
  if (run > 0) args.insert(args.end(), process.restart_args.begin(), process.restart_args.end());
  return args;
}

ProcessSet joining_a_running_system(ProcessSet set) {
  for (ProcessSpec& p : set) {
    p.argv = command_of_start(p, 1);
    p.restart_args.clear();  // in argv now: a restart adds them no second time
  }
  return set;
}

ProcessSet with_run_dir(ProcessSet set, const std::filesystem::path& run_dir) {
  for (ProcessSpec& p : set) {
    for (auto* args : {&p.argv, &p.restart_args}) {
      for (std::string& arg : *args) {
        for (size_t at = arg.find(kRunDirKey); at != std::string::npos;
             at = arg.find(kRunDirKey, at + run_dir.string().size()))
          arg.replace(at, kRunDirKey.size(), run_dir.string());
      }
    }
  }
  return set;
}

bool names_run_dir(const ProcessSet& set) {
  for (const ProcessSpec& p : set) {
    for (const auto* args : {&p.argv, &p.restart_args})
      for (const std::string& arg : *args)
        if (arg.find(kRunDirKey) != std::string::npos) return true;
  }
  return false;
}

namespace {
// Removes `option` and its value from `args`.
void drop_option(std::vector<std::string>& args, const std::string& option) {
  for (auto it = args.begin(); it != args.end();) {
    if (*it == option) {
      it = args.erase(it);
      if (it != args.end()) it = args.erase(it);
    } else {
      ++it;
    }
  }
}
}  // namespace

ProcessSet with_saved_map(ProcessSet set, const std::filesystem::path& map_dir, bool map_exists,
                          const SavedMapUse& use) {
  const bool localising = map_exists && use.localize_only;
  for (ProcessSpec& p : set) {
    const std::string& tool = p.argv.front();
    if (tool == "slam") {
      drop_option(p.argv, "--map");
      drop_option(p.argv, "--save-map");
      if (map_exists) p.argv.insert(p.argv.end(), {"--map", map_dir.string()});
      p.argv.insert(p.argv.end(), {"--save-map", map_dir.string()});
      if (localising && std::find(p.argv.begin(), p.argv.end(), "--localize-only") == p.argv.end())
        p.argv.push_back("--localize-only");
    } else if (tool == "mapper") {
      drop_option(p.argv, "--journal");
      p.argv.insert(p.argv.end(), {"--journal", (map_dir / "mapper.journal").string(), "--journal-is-map"});
      if (localising && use.update_map && std::find(p.argv.begin(), p.argv.end(), "--insert-located") == p.argv.end())
        p.argv.push_back("--insert-located");
    } else if (tool == "estimator" && map_exists) {
      // Every start awaits the map's world, the first one too (and for as long).
      drop_option(p.argv, "--await-world");
      drop_option(p.restart_args, "--await-world");
      char seconds[32];
      std::snprintf(seconds, sizeof(seconds), "%g", use.await_world_s);
      p.argv.insert(p.argv.end(), {"--await-world", seconds});
    }
  }
  return set;
}

ProcessSet read_process_sets(const std::filesystem::path& file) {
  if (!std::filesystem::is_regular_file(file)) throw InputError(file.string() + ": no such file");
  YAML::Node root;
  try {
    root = YAML::LoadFile(file.string());
  } catch (const YAML::Exception& e) {
    throw InputError(file.string() + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  if (!root.IsMap() || !root["processes"] || !root["processes"].IsSequence())
    throw InputError(file.string() + ": expected a top-level 'processes:' list");
  ProcessSet set;
  std::set<std::string> names;
  try {
    for (const auto& node : root["processes"]) {
      ProcessSpec p = read_process(file, node);
      if (!names.insert(p.name).second)
        throw InputError(where(file, node) + ": process '" + p.name + "' declared twice");
      set.push_back(std::move(p));
    }
  } catch (const YAML::Exception& e) {  // e.g. a list where a string belongs
    throw InputError(file.string() + ":" + std::to_string(e.mark.line + 1) + ": " + e.msg);
  }
  return set;
}

ProcessSet select(const ProcessSet& all, const std::string& set,
                  const std::vector<std::string>& only, const std::vector<std::string>& without) {
  if (set != "onboard" && set != "offboard" && set != "all")
    throw InputError("unknown process set '" + set + "' (onboard, offboard or all)");
  auto declared = [&](const std::string& name) {
    return std::any_of(all.begin(), all.end(), [&](const ProcessSpec& p) { return p.name == name; });
  };
  for (const auto* names : {&only, &without})
    for (const auto& n : *names)
      if (!declared(n)) throw InputError("no process named '" + n + "' in the process sets");
  auto listed = [](const std::vector<std::string>& v, const std::string& n) {
    return std::find(v.begin(), v.end(), n) != v.end();
  };
  ProcessSet out;
  for (const auto& p : all) {
    if (set != "all" && p.side != set) continue;
    if (!only.empty() && !listed(only, p.name)) continue;
    if (listed(without, p.name)) continue;
    out.push_back(p);
  }
  return out;
}

std::filesystem::path resolve_executable(const std::string& command,
                                         const std::filesystem::path& tool_dir) {
  auto runnable = [](const std::filesystem::path& p) {
    return std::filesystem::is_regular_file(p) && ::access(p.c_str(), X_OK) == 0;
  };
  if (command.find('/') != std::string::npos) {
    if (runnable(command)) return command;
    throw InputError("'" + command + "': not an executable file");
  }
  for (const auto& candidate : {tool_dir / ("kestrel-" + command), tool_dir / command})
    if (runnable(candidate)) return candidate;
  if (const char* path = std::getenv("PATH")) {
    std::istringstream dirs(path);
    for (std::string dir; std::getline(dirs, dir, ':');)
      if (!dir.empty() && runnable(std::filesystem::path(dir) / command))
        return std::filesystem::path(dir) / command;
  }
  throw InputError("'" + command + "': no kestrel-" + command + " in " + tool_dir.string() +
                   " (is it built?) and no '" + command + "' on PATH");
}

}  // namespace kestrel::launch
