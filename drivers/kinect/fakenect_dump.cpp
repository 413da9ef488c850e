#include "drivers/kinect/fakenect_dump.h"

#include <libfreenect.h>

#include <cstring>
#include <filesystem>
#include <memory>
#include <stdexcept>

#include "common/error.h"
#include "common/time.h"
#include "drivers/kinect/accelerometer.h"

namespace kestrel::kinect {
namespace fs = std::filesystem;
namespace {

constexpr int kWidth = 640;
constexpr int kHeight = 480;

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};

}  // namespace

uint32_t device_ticks(int64_t utime) {
  return static_cast<uint32_t>(static_cast<uint64_t>(utime) * 60u);
}

FakenectDumpWriter::FakenectDumpWriter(const std::string& folder) : folder_(folder) {
  std::error_code ec;
  fs::create_directories(folder_, ec);
  if (!fs::is_directory(folder_, ec)) throw InputError(folder_ + ": cannot create the dump folder");
  const std::string index = (fs::path(folder_) / "INDEX.txt").string();
  if (fs::exists(index, ec)) throw InputError(index + ": a fakenect dump is already there");
  // in-place: a recording, its index appended a line per frame as frames come
  index_ = std::fopen(index.c_str(), "w");
  if (!index_) throw InputError(index + ": cannot create");
}

FakenectDumpWriter::~FakenectDumpWriter() {
  if (index_) std::fclose(index_);
}

std::string FakenectDumpWriter::add_entry(char type, int64_t utime, const char* extension) {
  if (!index_) throw std::logic_error("FakenectDumpWriter: used after close()");
  if (entries_ > 0 && utime < last_utime_)
    throw std::invalid_argument("FakenectDumpWriter: entries must be added in time order");
  if (utime < 0) throw std::invalid_argument("FakenectDumpWriter: negative time");
  last_utime_ = utime;
  ++entries_;
  const std::string name = std::string(1, type) + "-" + format_seconds(utime) + "-" +
                           std::to_string(device_ticks(utime)) + "." + extension;
  if (std::fprintf(index_, "%s\n", name.c_str()) < 0) throw InputError(folder_ + "/INDEX.txt: write failed");
  return name;
}

void FakenectDumpWriter::write_file(const std::string& name, const std::string& header,
                                    const void* data, size_t size) {
  const std::string path = (fs::path(folder_) / name).string();
  // in-place: a recording, one file per frame as frames come
  std::unique_ptr<std::FILE, FileCloser> f(std::fopen(path.c_str(), "wb"));
  if (!f) throw InputError(path + ": cannot create");
  bool ok = std::fwrite(header.data(), 1, header.size(), f.get()) == header.size() &&
            std::fwrite(data, 1, size, f.get()) == size;
  ok = std::fclose(f.release()) == 0 && ok;
  if (!ok) throw InputError(path + ": write failed");
}

void FakenectDumpWriter::add_rgb(int64_t utime, const cv::Mat& rgb) {
  if (rgb.type() != CV_8UC3 || rgb.cols != kWidth || rgb.rows != kHeight)
    throw std::invalid_argument("FakenectDumpWriter: RGB must be 640x480 CV_8UC3");
  const cv::Mat contiguous = rgb.isContinuous() ? rgb : rgb.clone();
  write_file(add_entry('r', utime, "ppm"), "P6 640 480 255\n", contiguous.data, contiguous.total() * 3);
}

void FakenectDumpWriter::add_depth(int64_t utime, const cv::Mat& raw) {
  if (raw.type() != CV_16UC1 || raw.cols != kWidth || raw.rows != kHeight)
    throw std::invalid_argument("FakenectDumpWriter: depth must be 640x480 CV_16UC1");
  static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
                "fakenect dumps hold host-order uint16; this writer assumes little-endian");
  const cv::Mat contiguous = raw.isContinuous() ? raw : raw.clone();
  write_file(add_entry('d', utime, "pgm"), "P5 640 480 65535\n", contiguous.data, contiguous.total() * 2);
}

void FakenectDumpWriter::add_accel(int64_t utime, const Eigen::Vector3d& accel) {
  freenect_raw_tilt_state state;
  std::memset(&state, 0, sizeof state);  // padding too: the file is the struct's bytes
  state.accelerometer_x = mps2_to_counts(accel.x());
  state.accelerometer_y = mps2_to_counts(accel.y());
  state.accelerometer_z = mps2_to_counts(accel.z());
  state.tilt_angle = 0;
  state.tilt_status = TILT_STATUS_STOPPED;
  write_file(add_entry('a', utime, "dump"), "", &state, sizeof state);
}

void FakenectDumpWriter::close() {
  if (!index_) return;
  const bool ok = std::fclose(index_) == 0;
  index_ = nullptr;
  if (!ok) throw InputError(folder_ + "/INDEX.txt: write failed");
}

}  // namespace kestrel::kinect
