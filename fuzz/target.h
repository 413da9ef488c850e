#pragma once
// The fuzz targets: one per decoder of input from outside the process (a message off the bus,
// a file a user gives), each the code a process or tool runs on that input. kestrel-fuzz
// (fuzz/main.cpp) drives one under libFuzzer; test/fuzz/corpus_test.cpp replays every target's
// seeds and committed corpus under the sanitizers in every `./kestrel test`.
//
// The contract each target checks is the one common/error.h states: bad input only ever
// throws InputError (or, for a configuration file, is a usage error). A target returns
// whether its input was accepted; anything else it does — another exception, a crash, a
// sanitizer report, a hang, a property of the decoded value that does not hold (defect()) — is
// a defect for libFuzzer to report.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "common/error.h"

namespace kestrel::fuzz {

using Bytes = std::vector<uint8_t>;

struct Target {
  const char* name;   ///< as `./kestrel fuzz NAME` takes it
  const char* reads;  ///< the input it stands for, for --list and the README
  /// Runs the input: true if it was accepted, false if refused with InputError.
  bool (*run)(const uint8_t* data, size_t size);
  /// Well-formed inputs, made by kestrel's own writers: each is accepted (the replay test
  /// checks it, so that a target that refuses everything fails), and libFuzzer starts from them.
  std::vector<Bytes> (*seeds)();
};

/// Every target, in a fixed order.
const std::vector<Target>& targets();
/// The target named `name`, or null.
const Target* find_target(std::string_view name);

/// Reports a property of an accepted input that does not hold, and aborts (a libFuzzer crash).
[[noreturn]] void defect(const std::string& target, const std::string& what);

/// Runs `body`; false if it threw InputError (the only way bad input may end it).
template <class F>
bool accepted(F&& body) {
  try {
    body();
    return true;
  } catch (const InputError&) {
    return false;
  }
}

/// A path in this process's own scratch folder (removed at exit) holding `size` bytes of
/// `data`, for readers that take a path. The same `name` is rewritten by each input.
std::string scratch_file(const std::string& name, const uint8_t* data, size_t size);
std::string scratch_file(const std::string& name, std::string_view text);
/// The bytes of `s` (text seeds).
inline Bytes text(std::string_view s) { return Bytes(s.begin(), s.end()); }
/// The bytes of a file (for seeds written by a writer that takes a path).
Bytes file_bytes(const std::string& path);
/// The scratch folder itself.
const std::string& scratch_dir();

}  // namespace kestrel::fuzz
