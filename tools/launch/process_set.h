#pragma once
// Process sets: which kestrel processes `kestrel launch SET` starts, read from a small YAML
// file (tools/launch/processes.yaml is the default). Each process has a unique name, the
// command that runs it and a side (onboard or offboard); the set `all` is every process.
// Optionally `restart_args`: arguments added to the command when the launch starts the
// process again (--restart), for what only a restarted process needs (the estimator's
// --await-world: the first estimator of a launch defines the world, a restarted one must
// await the world that SLAM's map keeps).
//
// Invariants: a ProcessSet never holds two processes with one name, nor an empty command; a
// malformed file is an InputError naming the file (and line where yaml-cpp knows it).

#include <filesystem>
#include <string>
#include <vector>

namespace kestrel::launch {

struct ProcessSpec {
  std::string name;               ///< unique within a launch; also its log file's name
  std::vector<std::string> argv;  ///< argv[0] is a kestrel tool name ("vo") or a path
  std::string side;               ///< "onboard", "offboard" or "source"
  /// Added to argv when restarted (--restart), and at the first start when its side is launched
  /// alone (the other side may already be running, with a map).
  std::vector<std::string> restart_args{};
};

/// The command line of a process's `run`-th start (0: the first): argv, plus restart_args
/// from the first restart on.
std::vector<std::string> command_of_start(const ProcessSpec& process, int run);

using ProcessSet = std::vector<ProcessSpec>;

/// `set` with each process's restart_args made part of its command, for a launch of one side
/// alone (onboard or offboard): the other side may have run for a while already, so even a
/// first start joins a running system as a restart does (the estimator then awaits the
/// world of a SLAM that may have a map).
ProcessSet joining_a_running_system(ProcessSet set);

/// Every process the file declares, in file order. Throws InputError.
ProcessSet read_process_sets(const std::filesystem::path& file);

/// The processes of `set` ("onboard", "offboard" or "all"), minus those named in
/// `without`; with `only` non-empty, just those. Throws InputError for an unknown set or a
/// name in `only`/`without` that the file does not declare.
ProcessSet select(const ProcessSet& all, const std::string& set,
                  const std::vector<std::string>& only, const std::vector<std::string>& without);

/// Splits a command line on whitespace ("sim --world room"); no quoting, on purpose: the
/// commands here are tool names and plain arguments.
std::vector<std::string> split_command(const std::string& command);

/// `{run_dir}` in an argument (of restart_args too) becomes `run_dir`: a folder the launch
/// makes for itself, for files that must outlive a restarted process but not the launch (the
/// mapper's journal: a restarted mapper gets its map back, a new launch starts a new map).
ProcessSet with_run_dir(ProcessSet set, const std::filesystem::path& run_dir);
/// Whether an argument of `set` names `{run_dir}` (the launch makes the folder only then).
bool names_run_dir(const ProcessSet& set);

/// How a flight uses a building's saved map.
struct SavedMapUse {
  double await_world_s = 30.0;  ///< the estimator awaits the map's world this long
  /// On an existing map, SLAM localises only (no keyframes over the map)...
  bool localize_only = false;
  /// ...and the mapper updates the occupancy map from the frames SLAM locates in it.
  bool update_map = true;
};

/// `set` flying in a building's saved map (`kestrel launch --map DIR`, issue 41): SLAM saves its
/// map in `map_dir` on exit and, when `map_exists`, starts from it (relocalising the vehicle);
/// the mapper journals its keyframes in `map_dir`/mapper.journal, so its occupancy map follows
/// from flight to flight; and, on an existing map, the estimator awaits the map's world for
/// `use.await_world_s` (SLAM's first correction gives it) from its first start on. Localising
/// only, SLAM gets --localize-only and the mapper --insert-located (unless not update_map). The
/// processes are found by their tool (argv[0]: slam, mapper, estimator); others are unchanged.
ProcessSet with_saved_map(ProcessSet set, const std::filesystem::path& map_dir, bool map_exists,
                          const SavedMapUse& use = {});

/// Where argv[0] runs from: a path is used as given; a bare name `x` is `kestrel-x` in
/// `tool_dir` if present there, else `x` itself looked up in `tool_dir` and then on PATH.
/// Throws InputError naming the command when nothing runnable is found.
std::filesystem::path resolve_executable(const std::string& command,
                                         const std::filesystem::path& tool_dir);

}  // namespace kestrel::launch
