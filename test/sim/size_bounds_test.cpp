// Files that ask for an absurd size are refused before anything is sized from them: a ROS map
// with a resolution, origin, image header or extent beyond the bounds of occupancy_map.h, and
// a world file with a coordinate beyond world_file.h's. Each error names the file, the line
// and the field. The images are written by hand, so that a header can claim any size.

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <functional>
#include <string>

#include "common/error.h"
#include "drivers/sim/occupancy_map.h"
#include "drivers/sim/world_file.h"
#include "test/support/test_support.h"

namespace kestrel::sim {
namespace {


void write_text(const std::filesystem::path& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary) << bytes;
}

// A binary PGM of cols x rows pixels of grey `value`, with a comment line as GIMP writes one.
std::string pgm(int cols, int rows, uint8_t value) {
  return "P5\n# Created with The GIMP\n" + std::to_string(cols) + " " + std::to_string(rows) + "\n255\n" +
         std::string(static_cast<size_t>(cols) * rows, static_cast<char>(value));
}

// The start of a PNG, up to its IHDR chunk: enough to state a size, with no pixels at all.
std::string png_header(uint32_t width, uint32_t height) {
  std::string s("\x89PNG\r\n\x1a\n", 8);
  s += std::string("\0\0\0\x0d", 4) + "IHDR";
  for (uint32_t v : {width, height})
    for (int shift = 24; shift >= 0; shift -= 8) s += static_cast<char>((v >> shift) & 0xff);
  s += std::string("\x08\0\0\0\0", 5) + std::string(4, '\0');  // 8-bit grey; CRC not checked
  return s;
}

class MapBounds : public ::testing::Test {
 protected:
  // Writes the YAML (image, resolution, origin on lines 1, 2, 3) and returns its path.
  std::string map(const std::string& image, const std::string& resolution, const std::string& origin = "[0, 0, 0]") {
    const std::string path = (dir / ("m" + std::to_string(++count) + ".yaml")).string();
    write_text(path, "image: " + image + "\nresolution: " + resolution + "\norigin: " + origin + "\n");
    return path;
  }
  std::string image_path(const std::string& name) const { return (dir / name).string(); }

  kestrel::test::TempDir dir;
  int count = 0;
};

TEST_F(MapBounds, ResolutionMustBeBetweenAMillimetreAndTenMetres) {
  write_text(dir / "m.pgm", pgm(6, 4, 254));
  for (const std::string bad : {"1000", "0", "-0.05", "1e-9", "1e300"}) {
    const std::string yaml = map("m.pgm", bad);
    EXPECT_NE(kestrel::test::input_error_of([&] { read_occupancy_map(yaml); })
                  .find(yaml + ":2: 'resolution' must be in [0.001, 10] m per pixel, got "),
              std::string::npos)
        << bad << ": " << kestrel::test::input_error_of([&] { read_occupancy_map(yaml); });
  }
  const std::string nan = map("m.pgm", ".nan");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_occupancy_map(nan); }).find(nan + ":2: 'resolution' must be a number"),
            std::string::npos);
  const std::string coarsest = map("m.pgm", "10");
  EXPECT_EQ(read_occupancy_map(coarsest).image.cols, 6);  // the bound itself is a map
}

TEST_F(MapBounds, OriginMustBeWithinTenKilometres) {
  write_text(dir / "m.pgm", pgm(6, 4, 254));
  const std::string far = map("m.pgm", "0.05", "[1e12, 0, 0]");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_occupancy_map(far); })
                .find(far + ":3: 'origin' x and y must be within +-10000 m, got [1e+12, 0]"),
            std::string::npos)
      << kestrel::test::input_error_of([&] { read_occupancy_map(far); });
  const std::string south = map("m.pgm", "0.05", "[0, -2e4, 0]");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_occupancy_map(south); }).find(south + ":3: 'origin'"), std::string::npos);
  const std::string edge = map("m.pgm", "0.05", "[10000, -10000, 3.14]");
  EXPECT_NEAR(read_occupancy_map(edge).origin.x(), 1e4, 1e-9);
}

TEST_F(MapBounds, AMapWiderThanOneKilometreNamesResolutionAndImage) {
  write_text(dir / "wide.pgm", pgm(2000, 10, 254));
  const std::string wide = map("wide.pgm", "0.6");  // 1200 m
  EXPECT_NE(kestrel::test::input_error_of([&] { read_occupancy_map(wide); })
                .find(wide + ":2: 'resolution' 0.6 m per pixel makes the 2000 x 10 pixels of map image '" +
                      image_path("wide.pgm") + "' 1200 x 6 m; a map spans at most 1000 m"),
            std::string::npos)
      << kestrel::test::input_error_of([&] { read_occupancy_map(wide); });
  const std::string fits = map("wide.pgm", "0.5");  // 1000 m: the bound itself
  EXPECT_EQ(read_occupancy_map(fits).image.cols, 2000);
}

TEST_F(MapBounds, ImageHeadersClaimingTooManyPixelsAreRefusedBeforeDecoding) {
  // Neither file holds a single pixel: decoding would fail, or first allocate gigabytes.
  write_text(dir / "bomb.png", png_header(100000, 100000));
  write_text(dir / "bomb.pgm", "P5\n# big\n60000 60000\n255\n");
  for (const auto& [name, size] : std::vector<std::pair<std::string, std::string>>{
           {"bomb.png", "100000 x 100000"}, {"bomb.pgm", "60000 x 60000"}}) {
    const std::string yaml = map(name, "0.001");  // 100 m and 60 m: only the pixel count is wrong
    EXPECT_NE(kestrel::test::input_error_of([&] { read_occupancy_map(yaml); })
                  .find(yaml + ":1: map image '" + image_path(name) + "' is " + size +
                        " pixels, more than the 25000000 a map may have"),
              std::string::npos)
        << kestrel::test::input_error_of([&] { read_occupancy_map(yaml); });
  }
  write_text(dir / "empty.pgm", "P5\n0 10\n255\n");
  const std::string empty = map("empty.pgm", "0.05");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_occupancy_map(empty); }).find(empty + ":1: map image '" + image_path("empty.pgm") +
                                                               "' has no pixels (0 x 10 pixels)"),
            std::string::npos)
      << kestrel::test::input_error_of([&] { read_occupancy_map(empty); });
}

TEST_F(MapBounds, OnlyFormatsWhoseHeaderIsCheckedAreRead) {
  write_text(dir / "m.bmp", "BM" + std::string(60, '\0'));
  const std::string bmp = map("m.bmp", "0.05");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_occupancy_map(bmp); })
                .find(bmp + ":1: map image '" + image_path("m.bmp") + "' is not a PNG or PNM (PGM, PPM, PBM) file"),
            std::string::npos)
      << kestrel::test::input_error_of([&] { read_occupancy_map(bmp); });
  // A PNM's size may come after comment lines, as GIMP writes them.
  write_text(dir / "commented.pgm", "P5\n# one\n# two\n3\n# between\n2\n255\n" + std::string(6, '\xfe'));
  const OccupancyMap m = read_occupancy_map(map("commented.pgm", "0.05"));
  EXPECT_EQ(m.image.cols, 3);
  EXPECT_EQ(m.image.rows, 2);
}

TEST(WorldFileBounds, CoordinatesBeyondFiveHundredMetresNameTheField) {
  struct Case {
    std::string body;
    std::string expected;
  };
  const char* header = "kestrel-world 1\nmaterial p plaster\n";
  const Case cases[] = {
      {"wall p 0 0 1e12 0 z 0 3\n", "bad.world:3: wall: x1 '1e12' is beyond +-500 m (a world spans at most 1000 m)"},
      {"floor p 0 0 1 1 0\nwall p 0 0 1 0 z 0 1e9\n", "bad.world:4: wall: z1 '1e9' is beyond +-500 m"},
      {"floor p 0 0 1 1 0\nwall p 0 0 1 0 z 0 3 thick 600\n", "bad.world:4: wall: thick '600' is beyond +-500 m"},
      {"bounds -1000 0 0 1 1 1\n", "bad.world:3: bounds: x0 '-1000' is beyond +-500 m"},
      {"floor p 0 0 1 1 -501\n", "bad.world:3: floor: z '-501' is beyond +-500 m"},
      {"ceiling p 0 0 1 2e3 3\n", "bad.world:3: ceiling: y1 '2e3' is beyond +-500 m"},
      {"panel p 0 0 1e6 0 0 1\n", "bad.world:3: panel: x1 '1e6' is beyond +-500 m"},
      {"box p 0 0 0 1 1 501\n", "bad.world:3: box: z1 '501' is beyond +-500 m"},
      {"floor p 0 0 1 1 0\nlight 0 0 1e300\n", "bad.world:4: light: z '1e300' is beyond +-500 m"},
      {"floor p 0 0 1 1 0\nstart 0 -600 1 0\n", "bad.world:4: start: y '-600' is beyond +-500 m"},
  };
  for (const Case& c : cases) {
    const std::string message = kestrel::test::input_error_of([&] { parse_world(header + c.body, "bad.world"); });
    EXPECT_NE(message.find(c.expected), std::string::npos) << "got: " << message;
  }
  // A world of the full size is a world; a yaw is an angle, not bounded.
  const World w = parse_world(std::string(header) + "floor p -500 -500 500 500 0\nstart 0 0 1 7200\n", "big.world");
  EXPECT_NEAR(w.bounds().sizes().x(), 1000.0, 1e-9);
}

}  // namespace
}  // namespace kestrel::sim
