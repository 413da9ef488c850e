// PNM (Netpbm) images: a header of whitespace-separated decimal fields — "P5" width height
// maxval (bitmaps, P1 and P4, have no maxval) — with '#' comments, then the samples: binary
// (P4 bits packed per row, P5 grey, P6 R,G,B; big-endian when maxval > 255) or text (P1, P2,
// P3). Written here rather than through libnetpbm, which ends the process on a malformed file
// instead of reporting it.
#include <cctype>
#include <limits>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "common/error.h"
#include "common/image/image_io.h"

namespace kestrel::image {
namespace {

// Reads the header's decimal fields and, for plain files, the samples.
class Fields {
 public:
  explicit Fields(const std::vector<uint8_t>& bytes) : bytes_(bytes) {}

  /// The next decimal field, or -1 when there is none (end, or not a digit). Values beyond
  /// what any bound allows saturate rather than overflow.
  int64_t next() {
    skip_space_and_comments();
    int64_t value = 0;
    int digits = 0;
    for (; at_ < bytes_.size() && std::isdigit(bytes_[at_]); ++at_, ++digits)
      value = std::min<int64_t>(value * 10 + (bytes_[at_] - '0'), int64_t{1} << 40);
    return digits == 0 ? -1 : value;
  }
  /// The next '0' or '1' of a plain bitmap, or -1 when there is none.
  int64_t next_bit() {
    skip_space_and_comments();
    if (at_ >= bytes_.size() || (bytes_[at_] != '0' && bytes_[at_] != '1')) return -1;
    return bytes_[at_++] - '0';
  }
  /// After the header's last field: exactly one whitespace byte, then the binary samples.
  bool skip_one_space() {
    if (at_ >= bytes_.size() || !std::isspace(bytes_[at_])) return false;
    ++at_;
    return true;
  }
  size_t at() const { return at_; }
  void skip(size_t n) { at_ += n; }

 private:
  void skip_space_and_comments() {
    while (at_ < bytes_.size() && (std::isspace(bytes_[at_]) || bytes_[at_] == '#')) {
      if (bytes_[at_] == '#')
        while (at_ < bytes_.size() && bytes_[at_] != '\n' && bytes_[at_] != '\r') ++at_;
      else
        ++at_;
    }
  }
  const std::vector<uint8_t>& bytes_;
  size_t at_ = 0;
};

}  // namespace

cv::Mat decode_pnm(const std::vector<uint8_t>& bytes, const std::string& what) {
  const auto fail = [&](const std::string& why) -> cv::Mat { throw InputError(what + ": " + why); };
  if (bytes.size() < 2 || bytes[0] != 'P') return fail("not a PNM file");
  const char kind = static_cast<char>(bytes[1]);
  if (kind < '1' || kind > '6') return fail("not a PBM, PGM or PPM file");
  // Netpbm: whitespace follows the magic number ("P13" is no PBM); parse_header agrees.
  if (bytes.size() < 3 || !std::isspace(bytes[2])) return fail("no whitespace after the magic number P" + std::string(1, kind));
  const int channels = (kind == '3' || kind == '6') ? 3 : 1;
  const bool plain = kind <= '3';
  const bool bitmap = kind == '1' || kind == '4';

  Fields fields(bytes);
  fields.skip(2);
  const int64_t width = fields.next(), height = fields.next();
  // A bitmap has no maxval: its samples are bits, 1 black.
  const int64_t maxval = bitmap ? 1 : fields.next();
  if (width <= 0 || height <= 0) return fail("header has no valid width and height");
  if (maxval <= 0 || maxval > 65535) return fail("maxval must be 1 to 65535");
  const int depth = maxval > 255 ? CV_16U : CV_8U;
  const size_t sample_bytes = depth == CV_16U ? 2 : 1;
  const size_t samples = static_cast<size_t>(width) * static_cast<size_t>(height) * static_cast<size_t>(channels);
  if (static_cast<double>(width) * static_cast<double>(height) * static_cast<double>(static_cast<size_t>(channels) * sample_bytes) >
      static_cast<double>(kMaxDecodedBytes))
    return fail(std::to_string(width) + " x " + std::to_string(height) + " pixels is more than " +
                std::to_string(kMaxDecodedBytes >> 20) + " MiB decoded");

  cv::Mat image(static_cast<int>(height), static_cast<int>(width), CV_MAKETYPE(depth, channels));
  const auto store = [&](size_t i, int64_t v) {
    if (depth == CV_16U) reinterpret_cast<uint16_t*>(image.data)[i] = static_cast<uint16_t>(v);
    else image.data[i] = static_cast<uint8_t>(v);
  };
  // Bitmaps decode to 8-bit grey, 0 for a set bit and 255 for a clear one.
  const auto bit_to_grey = [](int64_t bit) { return bit ? int64_t{0} : int64_t{255}; };
  if (kind == '4') {
    if (!fields.skip_one_space()) return fail("no whitespace between the header and the bits");
    const size_t row_bytes = (static_cast<size_t>(width) + 7) / 8;
    const size_t need = row_bytes * static_cast<size_t>(height);
    if (bytes.size() - fields.at() < need)
      return fail("truncated: " + std::to_string(bytes.size() - fields.at()) + " bytes of bits, " +
                  std::to_string(need) + " needed");
    const uint8_t* p = bytes.data() + fields.at();
    for (int64_t r = 0; r < height; ++r)
      for (int64_t c = 0; c < width; ++c)
        store(static_cast<size_t>(r * width + c),
              bit_to_grey(p[static_cast<size_t>(r) * row_bytes + static_cast<size_t>(c / 8)] >> (7 - c % 8) & 1));
  } else if (kind == '1') {
    // Plain bitmap bits need no whitespace between them ("0110" is four samples).
    for (size_t i = 0; i < samples; ++i) {
      const int64_t v = fields.next_bit();
      if (v < 0) return fail("ends after " + std::to_string(i) + " of " + std::to_string(samples) + " bits");
      store(i, bit_to_grey(v));
    }
  } else if (plain) {
    for (size_t i = 0; i < samples; ++i) {
      const int64_t v = fields.next();
      if (v < 0) return fail("ends after " + std::to_string(i) + " of " + std::to_string(samples) + " samples");
      if (v > maxval) return fail("sample " + std::to_string(v) + " is above maxval " + std::to_string(maxval));
      store(i, v);
    }
  } else {
    if (!fields.skip_one_space()) return fail("no whitespace between the header and the samples");
    const size_t need = samples * sample_bytes;
    if (bytes.size() - fields.at() < need)
      return fail("truncated: " + std::to_string(bytes.size() - fields.at()) + " bytes of samples, " +
                  std::to_string(need) + " needed");
    const uint8_t* p = bytes.data() + fields.at();
    for (size_t i = 0; i < samples; ++i) {
      const int64_t v = sample_bytes == 2 ? (int64_t{p[2 * i]} << 8 | p[2 * i + 1]) : p[i];
      if (v > maxval) return fail("sample " + std::to_string(v) + " is above maxval " + std::to_string(maxval));
      store(i, v);
    }
  }
  if (channels == 3) cv::cvtColor(image, image, cv::COLOR_RGB2BGR);
  return image;
}

}  // namespace kestrel::image
