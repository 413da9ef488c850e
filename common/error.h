#pragma once
// Errors and exit codes shared by every kestrel tool and process.
//
// Bad input (a missing or malformed file, a corrupt message, NaN) is reported by throwing
// InputError with a one-line message that names the file (and line) or channel; the tool's
// main turns it into that line on stderr and exit code kBadInput. Nothing else is thrown for
// bad input, so a crash is always a bug.

#include <stdexcept>
#include <string>

namespace kestrel {

class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A device, the network or a service is not there (LCM cannot start, no Kinect): the tool's
/// main turns it into one line on stderr and exit code kExitUnavailable.
class UnavailableError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// "path:line: what" — the form every parser uses.
std::string at_line(const std::string& path, int line, const std::string& what);

/// Process exit codes (README "Exit codes").
enum ExitCode : int {
  kExitOk = 0,           ///< finished, nothing wrong
  kExitFailure = 1,      ///< ran, but the job failed (e.g. a peer never answered, a check failed)
  kExitUsage = 2,        ///< bad command line or configuration value
  kExitBadInput = 3,     ///< an input file or message was missing, malformed or corrupt
  kExitUnavailable = 4,  ///< a device, network or service is not available
  kExitInterrupted = 130 ///< stopped by SIGINT before finishing
};

}  // namespace kestrel
