// PNG through libspng: the colour type picks the decoded layout (image_io.h), spng does the
// rest. spng reports every problem (bad CRC, truncation, a chunk too large) as a return code.
#include <spng.h>

#include <algorithm>
#include <iterator>
#include <memory>
#include <stdexcept>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "common/error.h"
#include "common/image/image_io.h"
#include "common/atomic_file.h"

namespace kestrel::image {
namespace {

struct CtxFree {
  void operator()(spng_ctx* ctx) const { spng_ctx_free(ctx); }
};
using Ctx = std::unique_ptr<spng_ctx, CtxFree>;

[[noreturn]] void fail(const std::string& what, const std::string& why) {
  throw InputError(what + ": " + why);
}

void check(int status, const std::string& what, const char* step) {
  if (status != 0) fail(what, std::string("not a readable PNG (") + step + ": " + spng_strerror(status) + ")");
}

// The spng output format and OpenCV type for a colour type and bit depth (image_io.h): the
// file's own samples (SPNG_FMT_PNG, host byte order) for 8- and 16-bit images; grey of fewer
// bits scaled to 8; a palette expanded to colour.
struct Layout {
  int fmt;
  int cv_type;
  int flags = 0;
};

Layout layout_of(const spng_ihdr& h, bool has_transparency) {
  const int depth = h.bit_depth == 16 ? CV_16U : CV_8U;
  switch (h.color_type) {
    case SPNG_COLOR_TYPE_GRAYSCALE:
      return h.bit_depth < 8 ? Layout{SPNG_FMT_G8, CV_8UC1} : Layout{SPNG_FMT_PNG, CV_MAKETYPE(depth, 1)};
    case SPNG_COLOR_TYPE_GRAYSCALE_ALPHA:
      return {SPNG_FMT_PNG, CV_MAKETYPE(depth, 2)};
    case SPNG_COLOR_TYPE_TRUECOLOR:
      return {SPNG_FMT_PNG, CV_MAKETYPE(depth, 3)};
    case SPNG_COLOR_TYPE_TRUECOLOR_ALPHA:
      return {SPNG_FMT_PNG, CV_MAKETYPE(depth, 4)};
    case SPNG_COLOR_TYPE_INDEXED:
      return has_transparency ? Layout{SPNG_FMT_RGBA8, CV_8UC4, SPNG_DECODE_TRNS} : Layout{SPNG_FMT_RGB8, CV_8UC3};
    default:
      return {0, -1};
  }
}

// R,G,B(,A) <-> B,G,R(,A) in place: OpenCV's order is the reverse of the file's.
void swap_red_blue(cv::Mat& image) {
  if (image.channels() == 3) cv::cvtColor(image, image, cv::COLOR_RGB2BGR);
  if (image.channels() == 4) cv::cvtColor(image, image, cv::COLOR_RGBA2BGRA);
}

}  // namespace

cv::Mat decode_png(const std::vector<uint8_t>& bytes, const std::string& what) {
  Ctx ctx(spng_ctx_new(0));
  if (!ctx) throw std::bad_alloc();
  // A chunk larger than the image could ever need is a damaged length field, not metadata.
  check(spng_set_chunk_limits(ctx.get(), 64u << 20, 64u << 20), what, "limits");
  check(spng_set_png_buffer(ctx.get(), bytes.data(), bytes.size()), what, "buffer");
  spng_ihdr ihdr{};
  check(spng_get_ihdr(ctx.get(), &ihdr), what, "header");
  spng_trns trns{};
  const bool has_transparency = spng_get_trns(ctx.get(), &trns) == 0;
  const Layout layout = layout_of(ihdr, has_transparency);
  if (layout.cv_type < 0) fail(what, "unsupported PNG colour type " + std::to_string(ihdr.color_type));
  size_t size = 0;
  check(spng_decoded_image_size(ctx.get(), layout.fmt, &size), what, "size");
  if (size > kMaxDecodedBytes)
    fail(what, std::to_string(ihdr.width) + " x " + std::to_string(ihdr.height) + " pixels is more than " +
                   std::to_string(kMaxDecodedBytes >> 20) + " MiB decoded");
  cv::Mat image(static_cast<int>(ihdr.height), static_cast<int>(ihdr.width), layout.cv_type);
  if (image.total() * image.elemSize() != size) fail(what, "decoded size does not match its header");
  check(spng_decode_image(ctx.get(), image.data, size, layout.fmt, layout.flags), what, "pixels");
  // The chunks after the pixels, through IEND: a file cut after its image data (or with a
  // damaged last CRC) is a damaged file even though every pixel came out.
  check(spng_decode_chunks(ctx.get()), what, "end");
  // spng stops at IEND's type; its (constant) CRC must be the file's last four bytes too.
  static constexpr uint8_t kIend[] = {0, 0, 0, 0, 'I', 'E', 'N', 'D', 0xae, 0x42, 0x60, 0x82};
  if (bytes.size() < sizeof kIend || !std::equal(std::begin(kIend), std::end(kIend), bytes.end() - sizeof kIend))
    fail(what, "not a readable PNG (it does not end with an intact IEND chunk: cut short?)");
  swap_red_blue(image);
  return image;
}

std::vector<uint8_t> encode_png(const cv::Mat& image, int level, PngFilter filter) {
  if (image.empty()) throw std::invalid_argument("encode_png: empty image");
  if (image.depth() != CV_8U && image.depth() != CV_16U)
    throw std::invalid_argument("encode_png: only 8- and 16-bit images");
  if (image.channels() < 1 || image.channels() > 4) throw std::invalid_argument("encode_png: 1 to 4 channels");
  if (level < 0 || level > 9) throw std::invalid_argument("encode_png: level must be 0 to 9");
  static constexpr uint8_t kColourType[] = {SPNG_COLOR_TYPE_GRAYSCALE, SPNG_COLOR_TYPE_GRAYSCALE_ALPHA,
                                            SPNG_COLOR_TYPE_TRUECOLOR, SPNG_COLOR_TYPE_TRUECOLOR_ALPHA};
  cv::Mat rows;  // continuous, in the file's channel order
  if (image.channels() == 3) cv::cvtColor(image, rows, cv::COLOR_BGR2RGB);
  else if (image.channels() == 4) cv::cvtColor(image, rows, cv::COLOR_BGRA2RGBA);
  else rows = image.isContinuous() ? image : image.clone();

  Ctx ctx(spng_ctx_new(SPNG_CTX_ENCODER));
  if (!ctx) throw std::bad_alloc();
  const auto ok = [](int status, const char* step) {
    if (status != 0) throw std::runtime_error(std::string("encode_png: ") + step + ": " + spng_strerror(status));
  };
  ok(spng_set_option(ctx.get(), SPNG_ENCODE_TO_BUFFER, 1), "buffer");
  ok(spng_set_option(ctx.get(), SPNG_IMG_COMPRESSION_LEVEL, level), "level");
  static constexpr int kFilterChoice[] = {SPNG_FILTER_CHOICE_ALL, SPNG_FILTER_CHOICE_NONE, SPNG_FILTER_CHOICE_SUB,
                                          SPNG_FILTER_CHOICE_UP, SPNG_FILTER_CHOICE_AVG, SPNG_FILTER_CHOICE_PAETH};
  ok(spng_set_option(ctx.get(), SPNG_FILTER_CHOICE, kFilterChoice[static_cast<int>(filter)]), "filter");
  spng_ihdr ihdr{};
  ihdr.width = static_cast<uint32_t>(rows.cols);
  ihdr.height = static_cast<uint32_t>(rows.rows);
  ihdr.bit_depth = rows.depth() == CV_16U ? 16 : 8;
  ihdr.color_type = kColourType[rows.channels() - 1];
  ok(spng_set_ihdr(ctx.get(), &ihdr), "header");
  ok(spng_encode_image(ctx.get(), rows.data, rows.total() * rows.elemSize(), SPNG_FMT_PNG, SPNG_ENCODE_FINALIZE),
     "pixels");
  int status = 0;
  size_t length = 0;
  std::unique_ptr<void, decltype(&std::free)> png(spng_get_png_buffer(ctx.get(), &length, &status), &std::free);
  ok(status, "output");
  const auto* first = static_cast<const uint8_t*>(png.get());
  return {first, first + length};
}

void write_png(const std::string& path, const cv::Mat& image, int level, PngFilter filter) {
  const std::vector<uint8_t> bytes = encode_png(image, level, filter);
  write_file_atomically(path, bytes.data(), bytes.size());
}

}  // namespace kestrel::image
