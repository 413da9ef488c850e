// Files: the format from the first bytes, then the decoder for it.
#include <algorithm>
#include <cctype>
#include <fstream>
#include <iterator>

#include "common/error.h"
#include "common/image/image_io.h"

namespace kestrel::image {
namespace {

constexpr uint8_t kPngSignature[] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};

uint32_t be32(const std::vector<uint8_t>& b, size_t at) {
  return uint32_t{b[at]} << 24 | uint32_t{b[at + 1]} << 16 | uint32_t{b[at + 2]} << 8 | uint32_t{b[at + 3]};
}

bool is_png(const std::vector<uint8_t>& head) {
  return head.size() >= 8 && std::equal(std::begin(kPngSignature), std::end(kPngSignature), head.begin());
}

std::vector<uint8_t> read_bytes(const std::string& path, size_t limit) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open the image file");
  std::vector<uint8_t> bytes;
  char buffer[1 << 16];
  while (bytes.size() < limit && in.read(buffer, sizeof buffer).gcount() > 0)
    bytes.insert(bytes.end(), buffer, buffer + std::min<size_t>(static_cast<size_t>(in.gcount()), limit - bytes.size()));
  if (in.bad()) throw InputError(path + ": read error");
  return bytes;
}

}  // namespace

Header parse_header(const std::vector<uint8_t>& head) {
  if (is_png(head)) {
    static constexpr uint8_t kIhdr[] = {'I', 'H', 'D', 'R'};
    if (head.size() < 24 || !std::equal(std::begin(kIhdr), std::end(kIhdr), head.begin() + 12)) return {};
    return {Format::kPng, be32(head, 16), be32(head, 20)};
  }
  if (head.size() < 3 || head[0] != 'P' || head[1] < '1' || head[1] > '6' || !std::isspace(head[2])) return {};
  size_t at = 2;
  int64_t dims[2] = {0, 0};
  for (int64_t& d : dims) {
    while (at < head.size() && (std::isspace(head[at]) || head[at] == '#')) {
      if (head[at] == '#')
        while (at < head.size() && head[at] != '\n' && head[at] != '\r') ++at;
      else
        ++at;
    }
    int digits = 0;  // twelve digits are beyond any bound already; more would overflow
    for (; at < head.size() && std::isdigit(head[at]); ++at)
      if (++digits <= 12) d = d * 10 + (head[at] - '0');
    if (digits == 0) return {};
  }
  return {Format::kPnm, dims[0], dims[1]};
}

Header read_header(const std::string& path) {
  // Room for a PNM's comment lines (GIMP writes one).
  return parse_header(read_bytes(path, 4096));
}

cv::Mat read_image(const std::string& path) {
  // A compressed file is smaller than its pixels; a file beyond the decoded bound is refused
  // by the decoders' own size check on its header, so reading at most that much is enough.
  const std::vector<uint8_t> bytes = read_bytes(path, kMaxDecodedBytes + 4096);
  switch (parse_header(bytes).format) {
    case Format::kPng: return decode_png(bytes, path);
    case Format::kPnm: return decode_pnm(bytes, path);
    case Format::kUnknown: break;
  }
  if (bytes.empty()) throw InputError(path + ": empty image file");
  throw InputError(path + ": not a PNG or PNM (PBM, PGM, PPM) image");
}

}  // namespace kestrel::image
