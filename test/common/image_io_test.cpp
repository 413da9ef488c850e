// Image files (common/image/image_io.h): PNG decoded against a file assembled here byte by byte
// (so the byte order and channel order are checked against the format, not against our own
// encoder), PNM against hand-written files of every kind, encoder round trips over every layout,
// and the damage families: every truncation and every byte flip of a valid PNG gives a clean
// InputError or a decoded image (never a crash), headers claiming more pixels than the bound are
// refused before anything is allocated, missing, empty and unknown files are named.
#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "common/error.h"
#include "common/image/image_io.h"
#include "test/support/test_support.h"

namespace kestrel::image {
namespace {

using Bytes = std::vector<uint8_t>;

// The checksums the format needs, straight from their definitions (PNG spec, RFC 1950).
uint32_t crc32(const uint8_t* data, size_t n) {
  uint32_t c = 0xffffffffu;
  for (size_t i = 0; i < n; ++i) {
    c ^= data[i];
    for (int k = 0; k < 8; ++k) c = (c >> 1) ^ (0xedb88320u & (0u - (c & 1u)));
  }
  return c ^ 0xffffffffu;
}
uint32_t adler32(const Bytes& data) {
  uint32_t a = 1, b = 0;
  for (uint8_t v : data) {
    a = (a + v) % 65521;
    b = (b + a) % 65521;
  }
  return b << 16 | a;
}
void put32(Bytes& out, uint32_t v) {
  for (int shift = 24; shift >= 0; shift -= 8) out.push_back(static_cast<uint8_t>(v >> shift));
}
void chunk(Bytes& png, const char type[4], const Bytes& data) {
  put32(png, static_cast<uint32_t>(data.size()));
  const size_t start = png.size();
  png.insert(png.end(), type, type + 4);
  png.insert(png.end(), data.begin(), data.end());
  put32(png, crc32(png.data() + start, png.size() - start));
}

// A PNG of the given rows (each row's bytes as the file holds them, without the filter byte),
// its image data in one stored (uncompressed) deflate block.
Bytes assemble_png(uint32_t width, uint32_t height, uint8_t bit_depth, uint8_t colour_type,
                   const std::vector<Bytes>& rows) {
  Bytes png = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
  Bytes ihdr;
  put32(ihdr, width);
  put32(ihdr, height);
  ihdr.insert(ihdr.end(), {bit_depth, colour_type, 0, 0, 0});
  chunk(png, "IHDR", ihdr);
  Bytes raw;
  for (const Bytes& row : rows) {
    raw.push_back(0);  // filter type None
    raw.insert(raw.end(), row.begin(), row.end());
  }
  Bytes z = {0x78, 0x01, 0x01};  // zlib header; a final stored block
  const auto len = static_cast<uint16_t>(raw.size());
  z.insert(z.end(), {static_cast<uint8_t>(len), static_cast<uint8_t>(len >> 8), static_cast<uint8_t>(~len),
                     static_cast<uint8_t>(~len >> 8)});
  z.insert(z.end(), raw.begin(), raw.end());
  put32(z, adler32(raw));
  chunk(png, "IDAT", z);
  chunk(png, "IEND", {});
  return png;
}

Bytes text(const std::string& s) { return Bytes(s.begin(), s.end()); }


TEST(PngDecode, SixteenBitGreyIsReadBigEndianIntoHostOrder) {
  // 2 x 2: 0x0102, 0xffff / 0x0000, 5000 (0x1388), as the file stores them: big-endian.
  const Bytes png = assemble_png(2, 2, 16, 0, {{0x01, 0x02, 0xff, 0xff}, {0x00, 0x00, 0x13, 0x88}});
  const cv::Mat m = decode_png(png);
  ASSERT_EQ(m.type(), CV_16UC1);
  EXPECT_EQ(m.at<uint16_t>(0, 0), 0x0102);
  EXPECT_EQ(m.at<uint16_t>(0, 1), 0xffff);
  EXPECT_EQ(m.at<uint16_t>(1, 0), 0);
  EXPECT_EQ(m.at<uint16_t>(1, 1), 5000);
}

TEST(PngDecode, ColourComesOutBlueGreenRedAsOpenCvHasIt) {
  const Bytes rgb = assemble_png(2, 1, 8, 2, {{10, 20, 30, 40, 50, 60}});
  const cv::Mat m = decode_png(rgb);
  ASSERT_EQ(m.type(), CV_8UC3);
  EXPECT_EQ(m.at<cv::Vec3b>(0, 0), cv::Vec3b(30, 20, 10));
  EXPECT_EQ(m.at<cv::Vec3b>(0, 1), cv::Vec3b(60, 50, 40));
  const Bytes rgba = assemble_png(1, 1, 8, 6, {{1, 2, 3, 4}});
  const cv::Mat a = decode_png(rgba);
  ASSERT_EQ(a.type(), CV_8UC4);
  EXPECT_EQ(a.at<cv::Vec4b>(0, 0), cv::Vec4b(3, 2, 1, 4));
}

TEST(PngDecode, GreyAndGreyAlphaKeepTheirChannels) {
  EXPECT_EQ(decode_png(assemble_png(3, 1, 8, 0, {{0, 128, 255}})).type(), CV_8UC1);
  const cv::Mat ga = decode_png(assemble_png(1, 1, 8, 4, {{7, 9}}));
  ASSERT_EQ(ga.type(), CV_8UC2);
  EXPECT_EQ(ga.at<cv::Vec2b>(0, 0), cv::Vec2b(7, 9));
}

TEST(PngDecode, OneBitGreyIsScaledToEightBits) {
  // 8 pixels in one byte, 1 0 1 1 0 0 0 1.
  const cv::Mat m = decode_png(assemble_png(8, 1, 1, 0, {{0b10110001}}));
  ASSERT_EQ(m.type(), CV_8UC1);
  const std::array<int, 8> expected = {255, 0, 255, 255, 0, 0, 0, 255};
  for (int c = 0; c < 8; ++c) EXPECT_EQ(m.at<uint8_t>(0, c), expected[static_cast<size_t>(c)]) << c;
}

TEST(PngDecode, EveryTruncationIsAnInputErrorAndNoneCrashes) {
  const Bytes png = assemble_png(4, 3, 16, 0, std::vector<Bytes>(3, Bytes(8, 0x42)));
  for (size_t n = 0; n < png.size(); ++n) {
    const Bytes cut(png.begin(), png.begin() + static_cast<std::ptrdiff_t>(n));
    EXPECT_THROW(decode_png(cut, "cut.png"), InputError) << n << " of " << png.size() << " bytes";
  }
}

TEST(PngDecode, EveryByteFlipDecodesOrIsAnInputError) {
  const Bytes png = assemble_png(4, 3, 8, 2, std::vector<Bytes>(3, Bytes(12, 0x5a)));
  int refused = 0;
  for (size_t i = 0; i < png.size(); ++i) {
    Bytes bad = png;
    bad[i] ^= 0xff;
    try {
      const cv::Mat m = decode_png(bad, "flipped.png");
      EXPECT_FALSE(m.empty()) << i;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("flipped.png: "), std::string::npos) << e.what();
      ++refused;
    }
  }
  // Every chunk carries a CRC: a flip anywhere in a chunk's type or data is caught.
  EXPECT_GT(refused, static_cast<int>(png.size()) * 3 / 4);
}

TEST(PngDecode, AHeaderClaimingMorePixelsThanTheBoundIsRefusedBeforeDecoding) {
  const Bytes png = assemble_png(100000, 100000, 16, 6, {{0}});
  const std::string e = test::input_error_of([&] { decode_png(png, "huge.png"); });
  EXPECT_NE(e.find("huge.png: 100000 x 100000 pixels is more than 1024 MiB"), std::string::npos) << e;
}

TEST(PngEncode, EveryLayoutRoundTripsExactlyAtEveryLevel) {
  cv::RNG rng(7);
  for (const int type : {CV_8UC1, CV_8UC2, CV_8UC3, CV_8UC4, CV_16UC1, CV_16UC2, CV_16UC3, CV_16UC4}) {
    cv::Mat image(5, 7, type);
    rng.fill(image, cv::RNG::UNIFORM, 0, CV_MAT_DEPTH(type) == CV_16U ? 65536 : 256);
    for (const int level : {0, 1, 6, 9}) {
      const cv::Mat back = decode_png(encode_png(image, level));
      ASSERT_EQ(back.type(), type) << level;
      EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0.0) << "type " << type << " level " << level;
    }
  }
}

// With a fixed filter every row carries that filter's type byte (PNG 1.2, section 6: None 0,
// Sub 1, Up 2, Average 3, Paeth 4); at level 0 zlib stores the rows as they are (a two-byte
// zlib header, then one stored block: a byte of flags and four of lengths), so the bytes can be
// read in the file. Each filter decodes to the same pixels.
TEST(PngEncode, AFixedFilterIsWrittenOnEveryRowAndEveryFilterRoundTrips) {
  cv::RNG rng(11);
  cv::Mat image(6, 5, CV_16UC3);
  rng.fill(image, cv::RNG::UNIFORM, 0, 65536);
  const std::pair<PngFilter, int> fixed[] = {{PngFilter::kNone, 0}, {PngFilter::kSub, 1}, {PngFilter::kUp, 2},
                                             {PngFilter::kAverage, 3}, {PngFilter::kPaeth, 4}};
  const size_t row_bytes = 1 + 5 * 3 * 2;
  for (const auto& [filter, type_byte] : fixed) {
    const Bytes png = encode_png(image, 0, filter);
    const std::string text(png.begin(), png.end());
    const size_t idat = text.find("IDAT");
    ASSERT_NE(idat, std::string::npos);
    const size_t rows = idat + 4 + 2 + 5;
    ASSERT_LE(rows + 6 * row_bytes, png.size());
    for (int r = 0; r < 6; ++r) EXPECT_EQ(png[rows + r * row_bytes], type_byte) << "row " << r << " filter " << type_byte;
    EXPECT_EQ(cv::norm(decode_png(png), image, cv::NORM_INF), 0.0) << "filter " << type_byte;
  }
  for (const int level : {1, 9}) {
    const cv::Mat back = decode_png(encode_png(image, level, PngFilter::kAdaptive));
    EXPECT_EQ(cv::norm(back, image, cv::NORM_INF), 0.0) << "adaptive, level " << level;
  }
}

TEST(PngEncode, ARegionOfALargerImageIsWrittenAsItsOwnPixels) {
  cv::Mat big(10, 10, CV_16UC1);
  for (int r = 0; r < 10; ++r)
    for (int c = 0; c < 10; ++c) big.at<uint16_t>(r, c) = static_cast<uint16_t>(1000 * r + c);
  const cv::Mat region = big(cv::Rect(2, 3, 4, 5));
  EXPECT_EQ(cv::norm(decode_png(encode_png(region)), region, cv::NORM_INF), 0.0);
}

TEST(PngEncode, WhatPngCannotHoldIsRefused) {
  EXPECT_THROW(encode_png(cv::Mat()), std::invalid_argument);
  EXPECT_THROW(encode_png(cv::Mat(2, 2, CV_32FC1, cv::Scalar(1))), std::invalid_argument);
  cv::Mat five(2, 2, CV_8UC(5));  // (cv::Scalar fills at most four channels)
  std::memset(five.data, 0, five.total() * five.elemSize());
  EXPECT_THROW(encode_png(five), std::invalid_argument);
  EXPECT_THROW(encode_png(cv::Mat(2, 2, CV_8UC1, cv::Scalar(1)), 10), std::invalid_argument);
}

TEST(PnmDecode, PlainAndBinaryGreyGiveTheStoredSamples) {
  const cv::Mat plain = decode_pnm(text("P2\n# a comment\n3 2\n255\n0 1 2\n3 4 255\n"));
  ASSERT_EQ(plain.type(), CV_8UC1);
  EXPECT_EQ(plain.at<uint8_t>(1, 1), 4);
  EXPECT_EQ(plain.at<uint8_t>(1, 2), 255);
  Bytes binary = text("P5 2 1 65535\n");
  binary.insert(binary.end(), {0x01, 0x02, 0xff, 0xfe});  // big-endian 16-bit samples
  const cv::Mat wide = decode_pnm(binary);
  ASSERT_EQ(wide.type(), CV_16UC1);
  EXPECT_EQ(wide.at<uint16_t>(0, 0), 0x0102);
  EXPECT_EQ(wide.at<uint16_t>(0, 1), 0xfffe);
}

TEST(PnmDecode, ColourIsBlueGreenRed) {
  Bytes p6 = text("P6\n1 1\n255\n");
  p6.insert(p6.end(), {10, 20, 30});
  EXPECT_EQ(decode_pnm(p6).at<cv::Vec3b>(0, 0), cv::Vec3b(30, 20, 10));
  EXPECT_EQ(decode_pnm(text("P3 1 1 255 10 20 30")).at<cv::Vec3b>(0, 0), cv::Vec3b(30, 20, 10));
}

TEST(PnmDecode, BitmapsAreBlackWhereABitIsSet) {
  // 10 pixels a row: two bytes per row in P4, the last six bits padding.
  Bytes p4 = text("P4 10 1\n");
  p4.insert(p4.end(), {0b10000000, 0b01000000});
  const cv::Mat packed = decode_pnm(p4);
  ASSERT_EQ(packed.type(), CV_8UC1);
  EXPECT_EQ(packed.at<uint8_t>(0, 0), 0);
  EXPECT_EQ(packed.at<uint8_t>(0, 1), 255);
  EXPECT_EQ(packed.at<uint8_t>(0, 9), 0);
  EXPECT_EQ(packed.at<uint8_t>(0, 8), 255);
  const cv::Mat plain = decode_pnm(text("P1 3 1 011"));
  EXPECT_EQ(plain.at<uint8_t>(0, 0), 255);
  EXPECT_EQ(plain.at<uint8_t>(0, 1), 0);
  EXPECT_EQ(plain.at<uint8_t>(0, 2), 0);
}

TEST(PnmDecode, BadFilesSayWhatIsWrong) {
  struct Case {
    std::string bytes, expected;
  };
  const Case cases[] = {
      {"P7 1 1 255\n", "not a PBM, PGM or PPM file"},
      {"P5 0 3 255\n", "header has no valid width and height"},
      {"P5 2 2 0\n", "maxval must be 1 to 65535"},
      {"P5 2 2 70000\n", "maxval must be 1 to 65535"},
      {"P5 2 2 255\nab", "truncated: 2 bytes of samples, 4 needed"},
      {"P2 2 1 9\n3", "ends after 1 of 2 samples"},
      {"P2 2 1 9\n3 10", "sample 10 is above maxval 9"},
      {"P5 100000 100000 65535\n", "100000 x 100000 pixels is more than 1024 MiB"},
      {"P4 9 2\n\x01", "truncated: 1 bytes of bits, 4 needed"},
      // Found by fuzzing: decode_pnm took "P13" as P1 of width 3, parse_header as no PNM.
      {"P13 2 1\n1 0 1\n", "no whitespace after the magic number P1"},
      {"P5", "no whitespace after the magic number P5"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.bytes);
    const std::string e = test::input_error_of([&] { decode_pnm(text(c.bytes), "m.pgm"); });
    EXPECT_NE(e.find("m.pgm: " + c.expected), std::string::npos) << e;
  }
}

TEST(ImageFile, PngAndPnmAreToldApartByTheirFirstBytes) {
  test::TempDir dir;
  const cv::Mat grey(2, 3, CV_8UC1, cv::Scalar(77));
  write_png((dir / "a.png").string(), grey);
  std::ofstream(dir / "b.pgm", std::ios::binary) << "P2 3 2 255 77 77 77 77 77 77";
  for (const char* name : {"a.png", "b.pgm"}) {
    EXPECT_EQ(cv::norm(read_image((dir / name).string()), grey, cv::NORM_INF), 0.0) << name;
    const Header h = read_header((dir / name).string());
    EXPECT_EQ(h.width, 3) << name;
    EXPECT_EQ(h.height, 2) << name;
  }
  EXPECT_EQ(read_header((dir / "a.png").string()).format, Format::kPng);
  EXPECT_EQ(read_header((dir / "b.pgm").string()).format, Format::kPnm);
}

TEST(ImageFile, MissingEmptyAndUnknownFilesAreNamed) {
  test::TempDir dir;
  std::ofstream(dir / "empty.png").close();
  std::ofstream(dir / "x.bmp") << "BM not really";
  const std::string missing = (dir / "missing.png").string();
  EXPECT_EQ(test::input_error_of([&] { read_image(missing); }), missing + ": cannot open the image file");
  EXPECT_EQ(test::input_error_of([&] { read_image((dir / "empty.png").string()); }), (dir / "empty.png").string() + ": empty image file");
  EXPECT_EQ(test::input_error_of([&] { read_image((dir / "x.bmp").string()); }),
            (dir / "x.bmp").string() + ": not a PNG or PNM (PBM, PGM, PPM) image");
  EXPECT_EQ(test::input_error_of([&] { read_image(dir.path().string()); }).find(dir.path().string() + ": "), 0u);
  EXPECT_THROW(read_header(missing), InputError);
}

}  // namespace
}  // namespace kestrel::image
