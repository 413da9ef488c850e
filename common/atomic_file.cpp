#include "common/atomic_file.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <utility>

#include "common/error.h"

namespace kestrel {

namespace {

namespace fs = std::filesystem;

std::string folder_of(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  return parent.empty() ? std::string(".") : parent.string();
}

// The file a write to `path` should replace: a symbolic link's target (so the link stays a link),
// else `path` itself.
std::string resolve(const std::string& path) {
  std::error_code ec;
  if (!fs::is_symlink(path, ec)) return path;
  const fs::path existing = fs::canonical(path, ec);
  if (!ec) return existing.string();
  // A dangling link: the file it names is created.
  const fs::path link = fs::read_symlink(path, ec);
  if (ec) return path;
  return link.is_absolute() ? link.string() : (fs::path(path).parent_path() / link).string();
}

std::string errno_text() { return std::strerror(errno); }

// 0, or the errno of opening or fsync'ing `path`.
int fsync_path(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) return errno;
  const int error = ::fsync(fd) == 0 ? 0 : errno;
  ::close(fd);
  return error;
}

}  // namespace

AtomicFile::AtomicFile(std::string path) : path_(std::move(path)), target_(resolve(path_)) {
  struct stat st{};
  const bool exists = ::stat(target_.c_str(), &st) == 0;
  if (exists && S_ISDIR(st.st_mode)) throw InputError(path_ + ": is a folder, not a file to write");
  if (exists && !S_ISREG(st.st_mode)) {
    // in-place: a device or FIFO target, which a rename would replace
    out_.open(target_, std::ios::binary | std::ios::out | std::ios::trunc);
    if (!out_) throw InputError(path_ + ": cannot open for writing: " + errno_text());
    return;
  }
  // A name no one else uses: the pid keeps processes apart, the counter this process's writers.
  static std::atomic<unsigned> counter{0};
  const std::string name = fs::path(target_).filename().string();
  const std::string folder = folder_of(target_);
  int fd = -1;
  for (int attempt = 0; fd < 0 && attempt < 100; ++attempt) {
    temp_ = (fs::path(folder) / ("." + name + ".tmp-" + std::to_string(::getpid()) + "-" +
                                 std::to_string(counter.fetch_add(1))))
                .string();
    // in-place: the temporary, new (O_EXCL)
    fd = ::open(temp_.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd < 0 && errno != EEXIST) break;
  }
  if (fd < 0) {
    const std::string why = errno_text();
    temp_.clear();
    throw InputError(path_ + ": cannot write in " + folder + ": " + why);
  }
  // A replaced file keeps its permissions (0666 less the umask for a new one).
  if (exists) (void)::fchmod(fd, st.st_mode & 07777);
  ::close(fd);
  // in-place: the temporary
  out_.open(temp_, std::ios::binary | std::ios::out | std::ios::trunc);
  if (!out_) {
    const std::string why = errno_text();
    discard();
    throw InputError(path_ + ": cannot open for writing: " + why);
  }
}

AtomicFile::~AtomicFile() {
  if (!committed_) discard();
}

void AtomicFile::discard() noexcept {
  if (out_.is_open()) out_.close();
  if (!temp_.empty()) ::unlink(temp_.c_str());
  temp_.clear();
}

void AtomicFile::commit() {
  if (committed_) return;
  out_.flush();
  if (out_) out_.close();
  if (!out_) {
    const std::string why = errno_text();
    discard();
    throw InputError(path_ + ": write failed: " + why);
  }
  if (temp_.empty()) {  // written in place (a device or FIFO)
    committed_ = true;
    return;
  }
  if (const int error = fsync_path(temp_)) {
    discard();
    throw InputError(path_ + ": write failed (fsync): " + std::strerror(error));
  }
  if (::rename(temp_.c_str(), target_.c_str()) != 0) {
    const std::string why = errno_text();
    discard();
    throw InputError(path_ + ": cannot replace: " + why);
  }
  temp_.clear();
  committed_ = true;
  // The new name on disk too. Best effort: the file is whole under its name already, and some
  // file systems refuse fsync on a folder.
  (void)fsync_path(folder_of(target_));
}

void write_file_atomically(const std::string& path, const void* data, size_t size) {
  AtomicFile file(path);
  file.stream().write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  file.commit();
}

void write_file_atomically(const std::string& path, std::string_view bytes) {
  write_file_atomically(path, bytes.data(), bytes.size());
}

std::string keep_aside(const std::string& path, const std::string& tag) {
  // The time only makes the name tell the operator when; nothing computed depends on it.
  const auto utime = std::chrono::duration_cast<std::chrono::microseconds>(
                         std::chrono::system_clock::now().time_since_epoch())
                         .count();
  const std::string source = resolve(path);
  const std::string base = path + "." + tag + "-" + std::to_string(utime);
  for (int n = 1; n < 1000; ++n) {
    const std::string aside = n == 1 ? base : base + "-" + std::to_string(n);
    std::error_code ec;
    if (fs::symlink_status(aside, ec).type() != fs::file_type::not_found) continue;
    // The file itself, not a symbolic link to it: the link would show what replaces it.
    if (::link(source.c_str(), aside.c_str()) == 0) {
      (void)fsync_path(folder_of(path));
      return aside;
    }
    if (errno == EEXIST) continue;
    if (errno != EPERM && errno != EXDEV && errno != EMLINK && errno != ENOTSUP && errno != EOPNOTSUPP)
      throw InputError(path + ": cannot keep it as " + aside + ": " + errno_text());
    // No hard links here: a copy, complete on disk before anything replaces the original.
    // in-place: a new name beside the file (copy_options::none never overwrites)
    if (!fs::copy_file(source, aside, fs::copy_options::none, ec)) {
      fs::remove(aside, ec);
      throw InputError(path + ": cannot keep a copy as " + aside + ": " + ec.message());
    }
    if (const int error = fsync_path(aside)) {
      fs::remove(aside, ec);
      throw InputError(path + ": cannot keep a copy as " + aside + ": " + std::strerror(error));
    }
    (void)fsync_path(folder_of(path));
    return aside;
  }
  throw InputError(path + ": cannot keep it aside: every name " + base + "[-n] is taken");
}

void sync_path(const std::string& path) {
  if (const int error = fsync_path(path)) throw InputError(path + ": fsync failed: " + std::strerror(error));
}

}  // namespace kestrel
