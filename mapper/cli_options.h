#pragma once
// The mapper's options on a command line (and so in --config files and --print-config), shared
// by kestrel-mapper and kestrel-map so the two spell every option the same way. Every option
// shows its default in --help; values are checked by MapperOptions::validate(), whose error
// names the key.

#include "common/cli.h"
#include "mapper/map_node.h"
#include "mapper/mapper.h"

namespace kestrel::mapper {

/// Adds the map, scan and keyframe options of `o` to `app` (bound by reference: `o` must
/// outlive the parse).
void add_mapper_options(CLI::App& app, MapperOptions& o);

/// Runs o.validate(), turning its std::invalid_argument into a CLI::ValidationError (exit 2).
void check_mapper_options(const MapperOptions& o);
/// The same for the process's options (the map's, and the pose source, rate and journal).
void check_node_options(const NodeOptions& o);

}  // namespace kestrel::mapper
