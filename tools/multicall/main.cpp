// kestrel-tools: every kestrel tool and process in one executable. <build>/bin/kestrel-<name>
// is a symbolic link to it, and the tool that runs is the one the program was called by
// (argv[0]'s file name), so `kestrel-vo --help` and a process set's `vo` behave as separate
// programs would. `kestrel-tools <name> [args]` runs a tool by name; with no name it lists
// them. Why one executable: cmake/KestrelTargets.cmake, kestrel_tool.
#include <cstdio>
#include <cstring>
#include <string>

// Each tool's main, compiled in the generated batches inside namespace kestrel_tool_<id>.
#define KESTREL_TOOL(name, id) \
  namespace kestrel_tool_##id { \
  int main(int argc, char** argv); \
  }
#include "tool_table.h"
#undef KESTREL_TOOL

namespace {

struct Tool {
  const char* name;
  int (*main)(int, char**);
};

constexpr Tool kTools[] = {
#define KESTREL_TOOL(name, id) {name, &kestrel_tool_##id::main},
#include "tool_table.h"
#undef KESTREL_TOOL
};

const Tool* find(const std::string& name) {
  for (const Tool& t : kTools) {
    if (name == t.name) return &t;
  }
  return nullptr;
}

// A build configured with KESTREL_TOOLS holds only the tools it names (cmake/KestrelTargets.cmake).
#ifdef KESTREL_TOOLS_SUBSET
constexpr const char* kMissing = " in this build (configured with KESTREL_TOOLS, a subset of the tools)";
#else
constexpr const char* kMissing = "";
#endif

int list(std::FILE* out) {
  std::fprintf(out, "usage: kestrel-tools TOOL [ARGS...], or run bin/kestrel-TOOL; the tools:\n");
  for (const Tool& t : kTools) std::fprintf(out, "  %s\n", t.name);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  const std::string called = argc > 0 ? argv[0] : "";
  const std::string base = called.substr(called.find_last_of('/') + 1);  // npos + 1 == 0
  const std::string prefix = "kestrel-";
  if (base.compare(0, prefix.size(), prefix) == 0 && base != "kestrel-tools") {
    if (const Tool* t = find(base.substr(prefix.size()))) return t->main(argc, argv);
    std::fprintf(stderr, "kestrel-tools: error: no tool is called '%s'%s\n", base.c_str(), kMissing);
    list(stderr);
    return 2;  // kExitUsage (common/error.h)
  }
  if (argc < 2 || std::strcmp(argv[1], "--help") == 0 || std::strcmp(argv[1], "-h") == 0) {
    return list(argc < 2 ? stderr : stdout) + (argc < 2 ? 2 : 0);
  }
  if (const Tool* t = find(argv[1])) return t->main(argc - 1, argv + 1);
  std::fprintf(stderr, "kestrel-tools: error: no tool is called '%s'%s\n", argv[1], kMissing);
  list(stderr);
  return 2;
}
