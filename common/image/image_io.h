#pragma once
// Image files: PNG (read and write) and PNM (PBM/PGM/PPM, read), decoded into cv::Mat.
//
// Why not OpenCV's imgcodecs: Debian's build of it links GDAL, and with it about 140 shared
// libraries (HDF5, Poppler, MariaDB, PostgreSQL, ...). Loading them took 0.27 s of every
// process start, whatever the process did: a quarter of a second per tool run, per test case,
// per process a system test launches (docs/decisions/2026-12-02-process-start-and-test-code.md).
// PNG goes through libspng (maintained, no setjmp, errors as return codes); PNM is a header
// and raw samples, parsed here.
//
// The layout of a decoded image is the file's own, as cv::imread(path, IMREAD_UNCHANGED)
// gives it: 1 channel grey, 2 grey + alpha, 3 B,G,R, 4 B,G,R,A; CV_8U, or CV_16U for 16-bit
// files (host byte order). A palette PNG gives B,G,R (B,G,R,A when it has transparency);
// PNG grey of 1, 2 or 4 bits is scaled to 8. PNM samples are kept as stored (no scaling by
// maxval).
//
// Invariants: decoding never allocates more than kMaxDecodedBytes (a header claiming more is
// refused before any pixel is read); every failure throws InputError with a message that names
// the file (or "PNG data") and says what is wrong; nothing returns an empty Mat.
// Writing goes through write_file_atomically (common/atomic_file.h).

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include <opencv2/core/mat.hpp>

namespace kestrel::image {

/// The most a decoded image may occupy (1 GiB: a 16-bit RGBA 8192 x 8192 image is 512 MiB).
inline constexpr size_t kMaxDecodedBytes = size_t{1} << 30;

enum class Format { kUnknown, kPng, kPnm };

/// What a file's header says, read without decoding the image.
struct Header {
  Format format = Format::kUnknown;
  int64_t width = 0, height = 0;
};

/// The format and size from the first bytes of a file (PNG: the IHDR chunk; PNM: "P1".."P6"
/// then width and height among whitespace and '#' comments). kUnknown when neither.
Header parse_header(const std::vector<uint8_t>& head);
/// The header of the file at `path`; throws InputError when it cannot be read.
Header read_header(const std::string& path);

/// Decodes PNG bytes. `what` names the data in messages (a path, a channel).
cv::Mat decode_png(const std::vector<uint8_t>& bytes, const std::string& what = "PNG data");
/// Decodes binary (P4, P5, P6) or plain (P1, P2, P3) PNM bytes: 8- or 16-bit samples; bitmaps
/// as 8-bit grey, 0 where a bit is set (black) and 255 where it is clear.
cv::Mat decode_pnm(const std::vector<uint8_t>& bytes, const std::string& what = "PNM data");
/// Reads and decodes the PNG or PNM file at `path` (the format from its first bytes).
cv::Mat read_image(const std::string& path);

/// How each row is predicted from the ones before it before zlib compresses it (PNG's filter
/// types). kAdaptive tries all five on every row and keeps the one that looks smallest; it
/// costs as much as zlib at level 1. Any choice decodes to the same pixels.
enum class PngFilter { kAdaptive, kNone, kSub, kUp, kAverage, kPaeth };

/// PNG bytes of an 8- or 16-bit image of 1 to 4 channels (layout as above). `level` is zlib's
/// compression level, 0 (none) to 9 (smallest); 1 is fast and still halves depth images.
/// Throws std::invalid_argument for an image it cannot represent (float, 5 channels, empty).
std::vector<uint8_t> encode_png(const cv::Mat& image, int level = 6, PngFilter filter = PngFilter::kAdaptive);
/// encode_png written to `path` atomically.
void write_png(const std::string& path, const cv::Mat& image, int level = 6, PngFilter filter = PngFilter::kAdaptive);

}  // namespace kestrel::image
