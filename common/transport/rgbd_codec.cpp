#include "common/transport/rgbd_codec.h"

#include <turbojpeg.h>
#include <zstd.h>

#include <cmath>
#include <cstring>
#include <memory>

#include "common/error.h"
#include "common/numbers.h"
#include "common/text.h"
#include "common/transport/convert.h"

namespace kestrel::transport {
namespace {

using kestrel::rgbd_frame_t;

// One TurboJPEG handle per thread and direction (creating one costs more than compressing a
// small image), lent out for one call and thrown away unless that call succeeded.
// libjpeg-turbo 2.1 leaves a handle whose header read failed part-way (e.g. "Bogus Huffman
// table definition") in the middle of that read, and every later header read on it fails
// the same way: one corrupt frame then blinded vo, the mapper and rgbd-codec to every good
// frame after it (issue 38). No state of a failed call is reused, whatever the failure.
struct TjDeleter {
  void operator()(void* h) const { tjDestroy(h); }
};
using TjHandle = std::unique_ptr<void, TjDeleter>;

class TjLease {
 public:
  TjLease(TjHandle& slot, tjhandle (*init)()) : slot_(slot) {
    if (!slot_) slot_.reset(init());
    if (!slot_) throw std::runtime_error(std::string("TurboJPEG: ") + tjGetErrorStr2(nullptr));
  }
  ~TjLease() {
    if (!succeeded_) slot_.reset();  // a fresh handle is made on the next call
  }
  TjLease(const TjLease&) = delete;
  TjLease& operator=(const TjLease&) = delete;
  tjhandle get() const { return slot_.get(); }
  /// libjpeg's reason for the last failure, printable ASCII.
  std::string error() const { return tjGetErrorStr2(slot_.get()); }
  void succeeded() { succeeded_ = true; }

 private:
  TjHandle& slot_;
  bool succeeded_ = false;
};

std::vector<uint8_t> jpeg_compress(const cv::Mat& rgb, int quality) {
  thread_local TjHandle slot;
  TjLease handle(slot, tjInitCompress);
  unsigned char* out = nullptr;
  unsigned long size = 0;
  const int rc = tjCompress2(handle.get(), rgb.data, rgb.cols, static_cast<int>(rgb.step), rgb.rows,
                             TJPF_RGB, &out, &size, TJSAMP_420, quality, TJFLAG_ACCURATEDCT);
  if (rc != 0) {
    const std::string why = handle.error();
    tjFree(out);
    throw std::runtime_error("JPEG compression failed: " + why);
  }
  std::vector<uint8_t> bytes(out, out + size);
  tjFree(out);
  handle.succeeded();
  return bytes;
}

// Reads a JPEG's header with `handle` and checks it against the camera's size.
void check_jpeg_header(const TjLease& handle, const std::vector<uint8_t>& data, int width, int height,
                       const char* what) {
  int w = 0, h = 0, subsamp = 0, colorspace = 0;
  // libjpeg-turbo 2.1 takes a non-const source buffer but never writes to it.
  auto* src = const_cast<unsigned char*>(data.data());
  if (tjDecompressHeader3(handle.get(), src, data.size(), &w, &h, &subsamp, &colorspace) != 0)
    throw InputError(std::string(what) + ": corrupt JPEG colour image (" + handle.error() + ")");
  if (w != width || h != height) {
    throw InputError(std::string(what) + ": JPEG is " + std::to_string(w) + "x" +
                     std::to_string(h) + " but the camera is " + std::to_string(width) + "x" +
                     std::to_string(height));
  }
}

// The thread's decompression handle (header checks and decoding share it).
TjHandle& decompressor() {
  thread_local TjHandle slot;
  return slot;
}

void check_jpeg(const std::vector<uint8_t>& data, int width, int height, const char* what) {
  TjLease handle(decompressor(), tjInitDecompress);
  check_jpeg_header(handle, data, width, height, what);
  handle.succeeded();
}

cv::Mat jpeg_decompress(const std::vector<uint8_t>& data, int width, int height, const char* what) {
  TjLease handle(decompressor(), tjInitDecompress);
  auto corrupt = [&] {
    return InputError(std::string(what) + ": corrupt JPEG colour image (" + handle.error() + ")");
  };
  check_jpeg_header(handle, data, width, height, what);
  auto* src = const_cast<unsigned char*>(data.data());
  cv::Mat rgb(height, width, CV_8UC3);
  // A warning (a truncated or damaged scan, filled in grey) fails the call as well: the image
  // would not be the scene.
  if (tjDecompress2(handle.get(), src, data.size(), rgb.data, width, static_cast<int>(rgb.step),
                    height, TJPF_RGB, TJFLAG_ACCURATEDCT) != 0)
    throw corrupt();
  handle.succeeded();
  return rgb;
}

std::vector<uint8_t> raw_bytes(const cv::Mat& m) {
  std::vector<uint8_t> bytes(m.total() * m.elemSize());
  const size_t row = m.cols * m.elemSize();
  for (int r = 0; r < m.rows; ++r) std::memcpy(bytes.data() + r * row, m.ptr(r), row);
  return bytes;
}

static_assert(__BYTE_ORDER__ == __ORDER_LITTLE_ENDIAN__,
              "DEPTH_U16_MM is little-endian on the wire; add byte swapping for this host");

}  // namespace

rgbd_frame_t encode_rgbd(const RgbdFrame& frame, const RgbdEncoding& encoding) {
  frame.validate("encode_rgbd");
  rgbd_frame_t m{};
  m.utime = frame.utime;
  m.depth_utime = frame.depth_utime;
  m.seq = frame.seq;
  m.camera = to_message(frame.camera, frame.T_body_camera);
  m.camera.sensor = frame.sensor;

  m.rgb_encoding = frame.rgb.empty() ? rgbd_frame_t::RGB_NONE : encoding.rgb;
  if (m.rgb_encoding == rgbd_frame_t::RGB_RGB8) {
    m.rgb = raw_bytes(frame.rgb);
  } else if (m.rgb_encoding == rgbd_frame_t::RGB_JPEG) {
    cv::Mat contiguous = frame.rgb.isContinuous() ? frame.rgb : frame.rgb.clone();
    m.rgb = jpeg_compress(contiguous, encoding.jpeg_quality);
  } else if (m.rgb_encoding != rgbd_frame_t::RGB_NONE) {
    throw std::invalid_argument("encode_rgbd: unknown colour encoding");
  }
  m.rgb_size = static_cast<int32_t>(m.rgb.size());

  m.depth_encoding = frame.depth_mm.empty() ? rgbd_frame_t::DEPTH_NONE : encoding.depth;
  if (m.depth_encoding == rgbd_frame_t::DEPTH_U16_MM) {
    m.depth = raw_bytes(frame.depth_mm);
  } else if (m.depth_encoding == rgbd_frame_t::DEPTH_U16_MM_ZSTD) {
    const std::vector<uint8_t> raw = raw_bytes(frame.depth_mm);
    m.depth.resize(ZSTD_compressBound(raw.size()));
    const size_t n = ZSTD_compress(m.depth.data(), m.depth.size(), raw.data(), raw.size(),
                                   encoding.zstd_level);
    if (ZSTD_isError(n)) throw std::runtime_error(std::string("zstd: ") + ZSTD_getErrorName(n));
    m.depth.resize(n);
  } else if (m.depth_encoding != rgbd_frame_t::DEPTH_NONE) {
    throw std::invalid_argument("encode_rgbd: unknown depth encoding");
  }
  m.depth_size = static_cast<int32_t>(m.depth.size());
  return m;
}

namespace {

// decode_rgbd; with `defer_jpeg`, JPEG colour is checked but not decoded (rgb left empty).
RgbdFrame decode(const rgbd_frame_t& m, const char* what, bool defer_jpeg) {
  RgbdFrame f;
  f.utime = m.utime;
  f.depth_utime = m.depth_utime;
  f.seq = m.seq;
  f.camera = from_message(m.camera, what);
  f.T_body_camera = from_message(m.camera.T_body_camera, what);
  f.sensor = m.camera.sensor;
  check_plausible_camera(f.camera, f.T_body_camera, what);
  const int w = f.camera.width;
  const int h = f.camera.height;
  const size_t pixels = static_cast<size_t>(w) * static_cast<size_t>(h);
  auto fail = [&](const std::string& why) { throw InputError(std::string(what) + ": " + why); };

  switch (m.rgb_encoding) {
    case rgbd_frame_t::RGB_NONE:
      break;
    case rgbd_frame_t::RGB_RGB8:
      if (m.rgb.size() != pixels * 3)
        fail("RGB8 image has " + std::to_string(m.rgb.size()) + " bytes, expected " +
             std::to_string(pixels * 3));
      f.rgb = cv::Mat(h, w, CV_8UC3);
      std::memcpy(f.rgb.data, m.rgb.data(), m.rgb.size());
      break;
    case rgbd_frame_t::RGB_JPEG:
      if (defer_jpeg) check_jpeg(m.rgb, w, h, what);
      else f.rgb = jpeg_decompress(m.rgb, w, h, what);
      break;
    default:
      fail("unknown colour encoding " + std::to_string(m.rgb_encoding));
  }

  switch (m.depth_encoding) {
    case rgbd_frame_t::DEPTH_NONE:
      break;
    case rgbd_frame_t::DEPTH_U16_MM:
      if (m.depth.size() != pixels * 2)
        fail("depth image has " + std::to_string(m.depth.size()) + " bytes, expected " +
             std::to_string(pixels * 2));
      f.depth_mm = cv::Mat(h, w, CV_16UC1);
      std::memcpy(f.depth_mm.data, m.depth.data(), m.depth.size());
      break;
    case rgbd_frame_t::DEPTH_U16_MM_ZSTD: {
      // ZSTD_decompress makes a fresh context for each call: nothing outlives a corrupt frame.
      const unsigned long long n = ZSTD_getFrameContentSize(m.depth.data(), m.depth.size());
      if (n == ZSTD_CONTENTSIZE_ERROR || n == ZSTD_CONTENTSIZE_UNKNOWN || n != pixels * 2)
        fail("zstd depth image is corrupt or not " + std::to_string(w) + "x" + std::to_string(h));
      f.depth_mm = cv::Mat(h, w, CV_16UC1);
      const size_t got = ZSTD_decompress(f.depth_mm.data, pixels * 2, m.depth.data(), m.depth.size());
      if (ZSTD_isError(got)) fail(std::string("zstd depth image is corrupt (") + ZSTD_getErrorName(got) + ")");
      if (got != pixels * 2) fail("zstd depth image is corrupt (shorter than its header says)");
      break;
    }
    default:
      fail("unknown depth encoding " + std::to_string(m.depth_encoding));
  }
  if (m.rgb_encoding == rgbd_frame_t::RGB_NONE && f.depth_mm.empty()) fail("frame has neither colour nor depth");
  return f;
}

}  // namespace

RgbdFrame decode_rgbd(const rgbd_frame_t& m, const char* what) { return decode(m, what, false); }

RgbdDeferredColour decode_rgbd_deferring_colour(const rgbd_frame_t& m, const char* what) {
  RgbdDeferredColour d;
  d.frame = decode(m, what, true);
  if (m.rgb_encoding == rgbd_frame_t::RGB_JPEG) {
    // Shared: the callable is copied with the frame it belongs to, the bytes are not.
    auto jpeg = std::make_shared<const std::vector<uint8_t>>(m.rgb);
    d.colour = [jpeg, w = d.frame.camera.width, h = d.frame.camera.height, name = std::string(what)] {
      return jpeg_decompress(*jpeg, w, h, name.c_str());
    };
  }
  return d;
}

}  // namespace kestrel::transport
