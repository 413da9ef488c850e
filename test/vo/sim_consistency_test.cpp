// The reported covariance is consistent on the synthetic world, where the ground truth is
// exact: the room figure-eight rendered by kestrel-sim to a TUM folder, the odometry with the
// simulator camera's profile, which the export's camera.txt names (as it flies), and the NEES of every relative motion against the
// truth. Label `integration`: it renders 600 frames (about half a minute).
//
// Before the pixel noise was taken from the residuals, the covariance here was ~30 times too
// large (mean NEES 0.18): the model assumed 1.2 px where the rendered features show ~0.07 px,
// and the floors were the Kinect's.

#include <gtest/gtest.h>

#include <iostream>

#include "test/support/figures.h"
#include "test/support/test_support.h"
#include "vo/sequence_run.h"

namespace kestrel::vo {
namespace {

TEST(VoSimulator, CovarianceIsConsistentOnTheFigureEight) {
  test::TempDir dir;
  const std::string folder = (dir / "figure8").string();
  const auto sim = test::run({test::tool("sim").string(), "-q", "--world", "room", "--flight", "figure8", "--duration",
                              "20", "--seed", "1", "--tum", folder},
                             600.0);
  ASSERT_EQ(sim.exit_code, 0) << sim.err;
  const LoadedSequence sequence = load_tum_sequence(folder);
  ASSERT_GE(sequence.frames.size(), 600u);
  // The export's camera.txt names the camera that rendered it, as every offline tool reads it.
  ASSERT_EQ(tum_sensor(folder).name, "simulator");
  ASSERT_EQ(sequence.frames.front().sensor, "simulator");
  const SequenceRun run = run_sequence(sequence.frames, with_tum_sensor(folder, VoOptions{}));
  const RunFigures f = score(run, sequence.ground_truth);
  std::cout << "figure-eight: ATE " << f.ate_rmse_m << " m, NEES " << f.mean_nees << " (" << 100.0 * f.nees_within_95
            << " % within the 95 % bound, " << f.nees_frames << " frames)\n";
  EXPECT_EQ(f.ok, f.frames - 1) << "every frame but the first has a motion";
  EXPECT_TRUE(test::within_limit(f.ate_rmse_m, test::figure("vo.sim_room.ate_rmse")));
  // Near 6 (the dimension): neither over- nor under-confident by more than a third; most
  // frames inside the per-frame 95 % chi-square bound.
  EXPECT_TRUE(test::within_limit(f.mean_nees, test::figure("vo.sim_room.mean_nees")));
  EXPECT_GE(f.nees_within_95, 0.85);
}

}  // namespace
}  // namespace kestrel::vo
