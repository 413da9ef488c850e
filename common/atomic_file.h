#pragma once
// Output files written atomically: the bytes go to a temporary file in the target's own folder
// (".<name>.tmp-<pid>-<n>"), which is flushed, fsync'ed and then renamed over the target, and
// the folder is fsync'ed. So at every instant the target is either what it was before (or
// absent) or the whole new file: a run that fails, throws or is killed half-way never leaves a
// half-written file that looks whole, and never damages the file it was going to replace. Only
// a killed process can leave its temporary behind (named so that nobody takes it for output).
//
// Invariants: the target is touched only by commit(), by one rename(2); an AtomicFile destroyed
// without a successful commit() removes its temporary. A target that exists and is not a
// regular file (/dev/null, /dev/stdout, a FIFO) is written in place instead: renaming over a
// device would replace the device, and a stream has no "half-written file" to fear. A symbolic
// link is followed, so the file it points to is replaced, not the link.
//
// keep_aside() is the other half of "never destroy a file": what is to be replaced or
// rewritten (a damaged journal, a journal a reset starts again) is first kept under a new name.
//
// Errors (the folder cannot be written, a write or fsync fails, the disk is full) throw
// InputError naming the target, as the writers did before (exit 3).

#include <cstddef>
#include <fstream>
#include <string>
#include <string_view>

namespace kestrel {

class AtomicFile {
 public:
  /// Opens a temporary beside `path` for writing (binary: bytes are written as given).
  explicit AtomicFile(std::string path);
  ~AtomicFile();
  AtomicFile(const AtomicFile&) = delete;
  AtomicFile& operator=(const AtomicFile&) = delete;

  /// Where to write the content.
  std::ostream& stream() { return out_; }
  /// Flushes, fsyncs and renames the temporary over the target. Throws InputError naming the
  /// target if any step fails; the target is then as it was and the temporary is gone.
  void commit();

  const std::string& path() const { return path_; }
  /// The temporary's path ("" when writing in place or once committed).
  const std::string& temp_path() const { return temp_; }

 private:
  void discard() noexcept;

  std::string path_;   // as given, for messages
  std::string target_; // path_ with a symbolic link resolved
  std::string temp_;   // "" when writing in place
  // in-place: the temporary, renamed over the target by commit() (or a device or FIFO target itself)
  std::ofstream out_;
  bool committed_ = false;
};

/// Writes `bytes` to `path` atomically (an AtomicFile committed at once).
void write_file_atomically(const std::string& path, std::string_view bytes);
void write_file_atomically(const std::string& path, const void* data, size_t size);

/// Keeps the file at `path` as it is now under a new name beside it, "<path>.<tag>-<utime>"
/// (wall-clock microseconds, for the operator; "-2", "-3" appended if that is taken), before
/// something replaces it: a hard link (instant, no second copy on disk) or, where the file
/// system has none, a copy. The caller then replaces `path` by a rename (AtomicFile), never
/// writes into it, so the kept bytes stay as they were. Returns the new name; throws InputError
/// naming `path` if it cannot keep it (and then nothing has changed).
std::string keep_aside(const std::string& path, const std::string& tag);

/// fsync(2) of the file or folder at `path` (the folder after a rename, so that the new name
/// is on disk too). Throws InputError naming `path` if it fails.
void sync_path(const std::string& path);

}  // namespace kestrel
