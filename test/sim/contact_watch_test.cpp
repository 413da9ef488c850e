// ContactWatch against a known wall: the plane x = 3 (y in [-4, 4], z in [-1, 4]).
#include <gtest/gtest.h>

#include <stdexcept>

#include "drivers/sim/contact_watch.h"
#include "test/sim/sim_fixture.h"

namespace kestrel::sim {
namespace {

TEST(ContactWatch, CountsEachTimeTheSphereStartsTouchingTheWall) {
  ContactWatch watch(test::plane_world(false), 0.255);
  // Along x at y = 0, z = 1: touching while 3 - x <= 0.255, i.e. x >= 2.745.
  int starts = 0;
  auto fly = [&](double from, double to, double t0) {
    for (int k = 0; k <= 100; ++k) starts += watch.observe(t0 + 0.01 * k, {from + (to - from) * k / 100.0, 0.0, 1.0});
  };
  fly(0.0, 2.7, 0.0);  // up to 5 cm short of contact
  EXPECT_EQ(starts, 0);
  EXPECT_EQ(watch.contacts(), 0);
  EXPECT_LT(watch.first_contact_s(), 0.0);
  EXPECT_NEAR(watch.min_clearance_m(), 0.3, 1e-9);
  fly(2.7, 2.9, 1.0);  // in (the first position past 2.745 is x = 2.746, k = 23)
  EXPECT_EQ(starts, 1);
  EXPECT_NEAR(watch.first_contact_s(), 1.23, 1e-9);
  fly(2.9, 2.0, 2.0);  // out, and in again
  fly(2.0, 2.8, 3.0);
  EXPECT_EQ(watch.contacts(), 2);
  EXPECT_EQ(starts, 2);
  EXPECT_NEAR(watch.min_clearance_m(), 0.1, 1e-9);
  EXPECT_NEAR(watch.first_contact_s(), 1.23, 1e-9);
}

TEST(ContactWatch, PassingBesideTheWallsEndIsNoContact) {
  ContactWatch watch(test::plane_world(false), 0.25);
  // x = 3.5 beyond the wall's end y = 4 by 0.3 m: the nearest point is its edge (3, 4).
  for (int k = 0; k <= 100; ++k) watch.observe(0.01 * k, {3.0, 4.3, 1.0});
  EXPECT_EQ(watch.contacts(), 0);
  EXPECT_NEAR(watch.min_clearance_m(), 0.3, 1e-9);
  watch.observe(1.01, {3.0, 4.2, 1.0});
  EXPECT_EQ(watch.contacts(), 1);
  watch.reset();
  EXPECT_EQ(watch.contacts(), 0);
  EXPECT_LT(watch.first_contact_s(), 0.0);
}

TEST(ContactWatch, RefusesANonPositiveRadius) {
  EXPECT_THROW(ContactWatch(test::plane_world(false), 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace kestrel::sim
