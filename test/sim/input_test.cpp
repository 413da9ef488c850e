// Bad input names its file and line; the catalogue finds worlds; a seed fixes every byte.

#include <gtest/gtest.h>

#include <fstream>

#include "common/error.h"
#include "drivers/sim/flights.h"
#include "drivers/sim/occupancy_map.h"
#include "drivers/sim/simulation.h"
#include "drivers/sim/world_catalog.h"
#include "drivers/sim/world_file.h"
#include "sim_fixture.h"
#include "test/support/test_support.h"

namespace kestrel::sim {
namespace {


const char* kHeader = "kestrel-world 1\nmaterial p plaster\n";

TEST(WorldFileTest, MalformedStatementsNameFileAndLine) {
  struct Case {
    std::string body;
    std::string expected;
  };
  const Case cases[] = {
      {"wall q 0 0 1 0 z 0 3\n", "bad.world:3: wall: no material called 'q'"},
      {"floor p 0 0 1 1 0\nbounds 0 0 0 x 1 1\n", "bad.world:4: bounds: x1 'x' is not a finite number"},
      {"floor p 0 0 1 1 0\nwall p 0 0 0 0 z 0 1\n", "bad.world:4: wall: its two ends coincide"},
      {"floor p 0 0 1 1 nan\n", "bad.world:3: floor: z 'nan' is not a finite number"},
      {"box p 0 0 0 1 1 1 spin 3\n", "bad.world:3: box: unexpected 'spin'"},
      {"floor p 0 0 1 1 0\ntunnel 1 2\n", "bad.world:4: unknown statement 'tunnel'"},
      {"light 1 2\n", "bad.world:3: light: expected"},
      {"\n", "bad.world:3: the world has no surfaces"},
  };
  for (const Case& c : cases) {
    const std::string message = kestrel::test::input_error_of([&] { parse_world(kHeader + c.body, "bad.world"); });
    EXPECT_NE(message.find(c.expected), std::string::npos) << "got: " << message;
  }
  EXPECT_NE(kestrel::test::input_error_of([] { parse_world("kestrel-world 2\n", "v.world"); }).find("v.world:1: expected the header"),
            std::string::npos);
  EXPECT_NE(kestrel::test::input_error_of([] { load_world("/nonexistent/x.world"); }).find("/nonexistent/x.world: cannot open"),
            std::string::npos);
  EXPECT_NE(kestrel::test::input_error_of([] { load_world("atlantis"); }).find("unknown world 'atlantis'"), std::string::npos);
  EXPECT_NE(kestrel::test::input_error_of([] { load_world("stata"); }).find("--map"), std::string::npos);
}

// A world built for its geometry alone has every shape and collision query of the whole one,
// and says that it has no appearance.
TEST(WorldFileTest, AGeometryOnlyWorldAnswersCollisionQueriesAsTheWholeOne) {
  const std::string text = std::string(kHeader) +
                           "bounds 0 0 0 4 3 2.5\nfloor p 0 0 4 3 0\nwall p 0 0 4 0 z 0 2.5\n"
                           "wall p 4 3 0 3 z 0 2.5\nbox p 1.7 1.2 0 2.3 1.8 1.0\nlight 2 1.5 2.4 1\n";
  const World whole = parse_world(text, "room.world");
  const World geometry = parse_world(text, "room.world", WorldParts::kGeometry);
  EXPECT_TRUE(whole.has_appearance());
  EXPECT_FALSE(geometry.has_appearance());
  EXPECT_EQ(geometry.surfaces().size(), whole.surfaces().size());
  EXPECT_EQ(geometry.boxes().size(), whole.boxes().size());
  EXPECT_EQ(geometry.lights().size(), whole.lights().size());
  EXPECT_TRUE(geometry.bounds().isApprox(whole.bounds()));
  EXPECT_EQ(geometry.start(), whole.start());
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(1.0, 1.0, 1.0), Eigen::Vector3d(2.0, 1.5, 0.5), Eigen::Vector3d(3.5, 0.2, 2.0)}) {
    EXPECT_EQ(geometry.clearance(p), whole.clearance(p));
    EXPECT_EQ(geometry.is_free(p, 0.2), whole.is_free(p, 0.2));
  }
}

TEST(OccupancyMapTest, MalformedYamlNamesFileAndLine) {
  kestrel::test::TempDir dir;
  const auto write = [&](const std::string& name, const std::string& text) {
    std::ofstream(dir / name) << text;
    return (dir / name).string();
  };
  const std::string bad_number = write("a.yaml", "image: m.png\nresolution: fast\norigin: [0, 0, 0]\n");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_occupancy_map(bad_number); }).find(bad_number + ":2: 'resolution' must be a number"),
            std::string::npos);
  const std::string bad_origin = write("b.yaml", "image: m.png\nresolution: 0.05\norigin: [0, 0]\n");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_occupancy_map(bad_origin); }).find(bad_origin + ":3: 'origin'"), std::string::npos);
  const std::string no_image = write("c.yaml", "image: missing.png\nresolution: 0.05\norigin: [0, 0, 0]\n");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_occupancy_map(no_image); }).find(no_image + ":1: cannot read map image"),
            std::string::npos);
  const std::string broken = write("d.yaml", "image: m.png\nresolution: [0.05\n");
  EXPECT_NE(kestrel::test::input_error_of([&] { read_occupancy_map(broken); }).find(broken + ":"), std::string::npos);
}

TEST(CatalogueTest, BuiltInWorldsLoadWithTheirNames) {
  for (const std::string name : {"room", "floor", "office"}) {
    const World& w = test::builtin(name.c_str());
    EXPECT_EQ(w.name(), name);
    EXPECT_TRUE(w.is_free(w.start().head<3>(), 0.35)) << name << ": the start pose must be free";
  }
  EXPECT_NEAR(test::builtin("room").bounds().sizes().x(), 11.0, 1e-12);
  EXPECT_NEAR(test::builtin("floor").bounds().sizes().y(), 23.0, 1e-12);
}

// The first events of a simulation, as bytes.
std::vector<uint8_t> first_events(uint64_t seed) {
  const World& world = test::builtin("room");
  const auto flight = make_flight("figure8", world);
  SimulationOptions options;
  options.seed = seed;
  Simulation sim(world, *flight, options);
  std::vector<uint8_t> bytes;
  for (int i = 0; i < 24; ++i) {  // 3 frames and 21 IMU samples
    const SimEvent e = sim.next();
    if (e.kind == SimEvent::kFrame) {
      bytes.insert(bytes.end(), e.frame.rgb.datastart, e.frame.rgb.dataend);
      bytes.insert(bytes.end(), e.frame.depth_mm.datastart, e.frame.depth_mm.dataend);
    } else {
      const auto* p = reinterpret_cast<const uint8_t*>(e.imu.gyro.data());
      bytes.insert(bytes.end(), p, p + 3 * sizeof(double));
      p = reinterpret_cast<const uint8_t*>(e.imu.accel.data());
      bytes.insert(bytes.end(), p, p + 3 * sizeof(double));
    }
  }
  return bytes;
}

TEST(DeterminismTest, SameSeedSameBytesOtherSeedOtherBytes) {
  const auto a = first_events(7), b = first_events(7), c = first_events(8);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
}

}  // namespace
}  // namespace kestrel::sim
