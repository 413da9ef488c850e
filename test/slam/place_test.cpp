// Place recognition and loop verification on the synthetic room (synthetic_room.h), whose
// poses are exact: the true revisit is found and verified with the right relative pose, views
// of different places are rejected, a loop-free path yields no loop, and the vocabulary file
// round-trips and refuses corrupt files.

#include <gtest/gtest.h>

#include <opencv2/features2d.hpp>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <bitset>
#include <filesystem>
#include <fstream>
#include <random>

#include "common/error.h"
#include "common/geometry/se3.h"
#include "common/numbers.h"
#include "sensors/builtin_profiles.h"
#include "slam/place/binary_descriptor.h"
#include "slam/place/loop_verifier.h"
#include "slam/place/place_recognizer.h"
#include "test/slam/synthetic_room.h"
#include "test/support/test_support.h"

namespace kestrel::slam {
namespace {

using test::SyntheticRoom;

struct View {
  Eigen::Isometry3d T_world_camera;
  FrameFeatures features;
};

std::vector<View> views_along(const SyntheticRoom& room, const std::vector<Eigen::Isometry3d>& path) {
  const FeatureExtractor extractor;
  std::vector<View> views;
  int64_t utime = 1'000'000;
  for (const auto& T : path) {
    views.push_back({T, extractor.extract(room.render(T, test::test_camera(), utime))});
    utime += 200'000;
  }
  return views;
}

void expect_pose_near(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b, double metres, double radians) {
  EXPECT_LT(se3::translation_distance(a, b), metres);
  EXPECT_LT(se3::rotation_distance(a, b), radians);
}

// Hamming distances and the nearest two, against std::bitset's count on random descriptors
// with planted ties and near copies (hamming() is the portable bit-parallel sum; nearest_two
// runs the kernel this CPU gets).
TEST(BinaryDescriptor, HammingAndNearestTwoAgreeWithACountOfTheBits) {
  std::mt19937_64 rng(5);
  auto bits = [](const Descriptor& a, const Descriptor& b) {
    int n = 0;
    for (int w = 0; w < 4; ++w) n += static_cast<int>(std::bitset<64>(a[w] ^ b[w]).count());
    return n;
  };
  std::vector<Descriptor> train(300);
  for (auto& t : train) t = {rng(), rng(), rng(), rng()};
  train[17] = train[250];                      // a tie
  train[40] = {~0ULL, ~0ULL, ~0ULL, ~0ULL};    // 256 bits apart from zero
  for (int k = 0; k < 200; ++k) {
    Descriptor d = train[static_cast<size_t>(rng() % train.size())];
    for (int flips = static_cast<int>(rng() % 40); flips > 0; --flips) d[rng() % 4] ^= 1ULL << (rng() % 64);
    if (k == 0) d = {0, 0, 0, 0};
    // The expected answer by another method than the kernel's running minimum: every
    // (distance, index) pair sorted, the first two read off.
    std::vector<std::pair<int, int>> by_distance;
    for (size_t i = 0; i < train.size(); ++i) {
      const int h = bits(d, train[i]);
      ASSERT_EQ(hamming(d, train[i]), h);
      by_distance.emplace_back(h, static_cast<int>(i));
    }
    std::sort(by_distance.begin(), by_distance.end());
    const NearestTwo got = nearest_two(d, train);
    ASSERT_EQ(got.index, by_distance[0].second) << k;
    ASSERT_EQ(got.best, by_distance[0].first) << k;
    ASSERT_EQ(got.second, by_distance[1].first) << k;
  }
  EXPECT_EQ(hamming(train[40], Descriptor{}), 256);
  EXPECT_EQ(nearest_two(train[250], train).index, 17) << "a tie keeps the lower index";
  EXPECT_EQ(nearest_two(train[250], train).second, 0);
  EXPECT_EQ(nearest_two(train[0], {}).index, -1);
}

// What loop verification took from OpenCV before: BFMatcher::knnMatch(NORM_HAMMING, k = 2)
// gives the same nearest index (ties: the lower) and the same two distances, on sets from two
// rows up, with ties and copies planted.
TEST(BinaryDescriptor, NearestTwoIsWhatOpenCvsBruteForceMatcherFinds) {
  std::mt19937 rng(11);
  for (int rows : {2, 3, 40, 257}) {
    cv::Mat train(rows, 32, CV_8UC1), queries(60, 32, CV_8UC1);
    cv::randu(train, cv::Scalar::all(0), cv::Scalar::all(256));
    cv::randu(queries, cv::Scalar::all(0), cv::Scalar::all(256));
    train.row(0).copyTo(train.row(rows - 1));  // a tie for every query
    for (int q = 0; q < 20; ++q) train.row(static_cast<int>(rng() % static_cast<unsigned>(rows))).copyTo(queries.row(q));
    std::vector<std::vector<cv::DMatch>> knn;
    cv::BFMatcher(cv::NORM_HAMMING).knnMatch(queries, train, knn, 2);
    const std::vector<Descriptor> t = to_descriptors(train);
    for (int q = 0; q < queries.rows; ++q) {
      const NearestTwo n = nearest_two(descriptor_at(queries, q), t);
      ASSERT_EQ(knn[static_cast<size_t>(q)].size(), 2u);
      EXPECT_EQ(n.index, knn[static_cast<size_t>(q)][0].trainIdx) << rows << " rows, query " << q;
      EXPECT_EQ(n.best, static_cast<int>(knn[static_cast<size_t>(q)][0].distance)) << rows << " rows, query " << q;
      EXPECT_EQ(n.second, static_cast<int>(knn[static_cast<size_t>(q)][1].distance)) << rows << " rows, query " << q;
    }
  }
}

TEST(FrameFeatures, PointsLieOnTheRenderedSurfaces) {
  const SyntheticRoom room(3, 3.0, 2.5, 2.5);
  const Eigen::Isometry3d T = test::level_camera({0.5, 0.2, 1.0}, 0.3);
  const FrameFeatures f = FeatureExtractor().extract(room.render(T, test::test_camera(), 1));
  ASSERT_GT(f.num_points(), 100u);
  for (size_t i = 0; i < f.size(); ++i) {
    if (!f.has_point(i)) continue;
    const Eigen::Vector3d p = T * f.points[i];
    // On a wall (|x| = 3 or |y| = 2.5), the floor or the ceiling, within the depth quantisation.
    const double off = std::min({std::abs(std::abs(p.x()) - 3.0), std::abs(std::abs(p.y()) - 2.5),
                                 std::abs(p.z()), std::abs(p.z() - 2.5)});
    EXPECT_LT(off, 0.01) << "point " << i << " at " << p.transpose();
  }
}

TEST(LoopVerifier, AcceptsTheSamePlaceFromAnotherViewWithTheTrueRelativePose) {
  const SyntheticRoom room(3, 3.0, 2.5, 2.5);
  const auto views = views_along(room, {test::level_camera({0.0, 0.0, 1.0}, 0.0),
                                        test::level_camera({0.4, 0.3, 1.1}, 0.25)});
  const LoopConstraint c = verify_loop(views[1].features, views[0].features, VerificationOptions{}, 7);
  ASSERT_TRUE(c.accepted) << c.reason;
  EXPECT_GE(c.inliers, 10);
  const Eigen::Isometry3d truth = views[0].T_world_camera.inverse() * views[1].T_world_camera;
  expect_pose_near(c.T_candidate_query, truth, 0.02, 0.01);
  // The information is positive definite (a usable pose-graph edge).
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Matrix6d>(c.information).eigenvalues().minCoeff(), 0.0);
}

// A loop with a Kinect keyframe at either end takes the Kinect's 1 degree rotation floor (its
// per-frame errors, loop_verifier.h); the simulator's camera keeps the options' own floors.
TEST(LoopVerifier, AKinectsLoopTakesTheKinectsRotationFloor) {
  const sensors::SensorProfile& sim_camera = sensors::builtin_profile("simulator");
  const sensors::SensorProfile& kinect = sensors::builtin_profile("kinect1");
  VerificationOptions o;
  o.rotation_sigma_floor_rad = 0.001;
  EXPECT_EQ(loop_verification(o, sim_camera, sim_camera).rotation_sigma_floor_rad, 0.001);
  EXPECT_EQ(loop_verification(o, kinect, sim_camera).rotation_sigma_floor_rad, kPi / 180.0);  // kinect1.yaml's 1 degree
  EXPECT_EQ(loop_verification(o, sim_camera, kinect).rotation_sigma_floor_rad, kPi / 180.0);
  EXPECT_EQ(loop_verification(o, kinect, kinect).translation_sigma_floor_m, o.translation_sigma_floor_m);
  o.rotation_sigma_floor_rad = 0.05;  // a larger floor of the options' own stays
  EXPECT_EQ(loop_verification(o, kinect, kinect).rotation_sigma_floor_rad, 0.05);

  // On a real pair: the same constraint, its rotation at least 1 degree uncertain per axis (the
  // edge's covariance, the information's inverse; its rotation error is vec(q), half the
  // angle, hence a quarter of the variance), which the simulator's floors do not give.
  const SyntheticRoom room(3, 3.0, 2.5, 2.5);
  const auto views = views_along(room, {test::level_camera({0.0, 0.0, 1.0}, 0.0),
                                        test::level_camera({0.4, 0.3, 1.1}, 0.25)});
  const VerificationOptions sim;
  const LoopConstraint a = verify_loop(views[1].features, views[0].features, sim, 7);
  const LoopConstraint b = verify_loop(views[1].features, views[0].features,
                                       loop_verification(sim, kinect, kinect), 7);
  ASSERT_TRUE(a.accepted && b.accepted) << a.reason << " / " << b.reason;
  EXPECT_TRUE(a.T_candidate_query.isApprox(b.T_candidate_query));
  const Eigen::Vector3d sim_var = a.information.inverse().diagonal().tail<3>();
  const Eigen::Vector3d kinect_var = b.information.inverse().diagonal().tail<3>();
  const double floor_var = std::pow(0.5 * kPi / 180.0, 2);
  EXPECT_LT(sim_var.maxCoeff(), 0.5 * floor_var) << sim_var.transpose();
  EXPECT_GT(kinect_var.minCoeff(), 0.95 * floor_var) << kinect_var.transpose();
}

// A wall seen from half a metre: the inliers span 14 cm (standard deviation) across the image's
// short side. A loop closure refuses that (no prior to check it against, min_spread_m), but there
// are hundreds of inliers and they fix the pose: re-anchoring, which checks the location against
// its prediction, judges them by their precision alone (min_spread_m = 0) and takes them.
TEST(LoopVerifier, AcceptsAWallSeenFromCloseUpByItsPrecision) {
  const SyntheticRoom room(3, 3.0, 2.5, 2.5);
  const auto views = views_along(room, {test::level_camera({2.45, 0.0, 1.0}, 0.0),
                                        test::level_camera({2.42, 0.04, 1.02}, 0.03)});
  EXPECT_FALSE(verify_loop(views[1].features, views[0].features, VerificationOptions{}, 7).accepted);
  VerificationOptions by_precision;
  by_precision.min_spread_m = 0.0;
  const LoopConstraint c = verify_loop(views[1].features, views[0].features, by_precision, 7);
  ASSERT_TRUE(c.accepted) << c.reason;
  EXPECT_GE(c.inliers, 50);
  const Eigen::Isometry3d truth = views[0].T_world_camera.inverse() * views[1].T_world_camera;
  expect_pose_near(c.T_candidate_query, truth, 0.01, 0.005);
}

// Inliers along one image row lie near one line on the wall: the rotation about that line is
// left to the noise, so the candidate is refused by its precision, however many inliers.
TEST(LoopVerifier, RejectsInliersAlongALine) {
  const SyntheticRoom room(3, 3.0, 2.5, 2.5);
  const auto views = views_along(room, {test::level_camera({0.0, 0.0, 1.0}, 0.0),
                                        test::level_camera({0.1, 0.05, 1.0}, 0.05)});
  constexpr double kBand = 4.0;  // pixels either side of the centre row: +-4 cm on the wall 3 m away
  auto keep_one_row = [](FrameFeatures f) {
    const double row = f.camera.cy;
    for (size_t i = 0; i < f.size(); ++i)
      if (std::abs(static_cast<double>(f.keypoints[i].pt.y) - row) > kBand) f.points[i].setConstant(std::nan(""));
    return f;
  };
  VerificationOptions by_precision;
  by_precision.min_spread_m = 0.0;
  const LoopConstraint whole = verify_loop(views[1].features, views[0].features, by_precision, 7);
  ASSERT_TRUE(whole.accepted) << whole.reason;
  const LoopConstraint line =
      verify_loop(keep_one_row(views[1].features), keep_one_row(views[0].features), by_precision, 7);
  EXPECT_GE(line.matches, 10) << "the row must keep enough matches for the test to mean something";
  EXPECT_FALSE(line.accepted) << line.inliers << " inliers";
  EXPECT_NE(line.reason.find("rotation"), std::string::npos) << line.reason;
}

TEST(LoopVerifier, RejectsViewsOfDifferentPlaces) {
  const SyntheticRoom room(3, 3.0, 2.5, 2.5);
  const auto views = views_along(room, {test::level_camera({0.0, 0.0, 1.0}, 0.0),
                                        test::level_camera({0.0, 0.0, 1.0}, kPi),
                                        test::level_camera({0.0, 0.0, 1.0}, kPi / 2)});
  for (const auto& [q, c] : {std::pair{1, 0}, std::pair{2, 0}, std::pair{2, 1}}) {
    const LoopConstraint r = verify_loop(views[q].features, views[c].features, VerificationOptions{}, 7);
    EXPECT_FALSE(r.accepted) << "views " << q << " and " << c << " see different walls";
  }
}

TEST(LoopVerifier, RejectsAViewWhoseDepthDisagrees) {
  // The same image with every depth scaled by 1.3 (a depth camera out of calibration): the
  // pixels match perfectly, no rigid motion explains the 3-D points.
  const SyntheticRoom room(3, 3.0, 2.5, 2.5);
  const auto views = views_along(room, {test::level_camera({0.0, 0.0, 1.0}, 0.0)});
  FrameFeatures warped = views[0].features;
  for (size_t i = 0; i < warped.size(); ++i) {
    if (warped.has_point(i)) warped.points[i] *= 1.3;
  }
  const LoopConstraint r = verify_loop(warped, views[0].features, VerificationOptions{}, 7);
  EXPECT_FALSE(r.accepted) << r.inliers << " inliers";
}

TEST(PlaceRecognizer, FindsTheTrueRevisitOfALoop) {
  // Round a circle once and a quarter: the last views revisit the first ones.
  const SyntheticRoom room(5, 3.0, 2.5, 2.5);
  const int n = 45;
  const auto path = test::circle_path(n, 1.0, 1.25);
  const auto views = views_along(room, path);
  PlaceRecognizer places;
  int revisits_found = 0;
  for (int k = 0; k < n; ++k) {
    // Only views at least 20 steps (4 s) older are candidates, as in SLAM.
    const auto matches = places.query(views[k].features.descriptors, 15, [k](int e) { return e <= k - 20; });
    for (const BowMatch& m : matches) {
      const LoopConstraint c = verify_loop(views[k].features, views[m.entry].features, VerificationOptions{}, 1);
      if (!c.accepted) continue;
      // Every accepted closure is a true one with the true relative pose.
      expect_pose_near(c.T_candidate_query, views[m.entry].T_world_camera.inverse() * views[k].T_world_camera,
                       0.05, 0.02);
      ++revisits_found;
      break;
    }
    places.add(views[k].features.descriptors);
  }
  // Steps 36..44 revisit steps 0..8 (a full turn is 36 steps).
  EXPECT_GE(revisits_found, 5);
  EXPECT_GE(places.trainings(), 3) << "the online vocabulary is retrained as keyframes double";
}

// A forgotten keyframe (SLAM thinned it) is never a candidate again, through later online
// trainings too, and the others keep their numbers: entry i is still the i-th keyframe added.
TEST(PlaceRecognizer, AForgottenKeyframeIsNeverACandidateAgain) {
  const SyntheticRoom room(5, 3.0, 2.5, 2.5);
  const auto views = views_along(room, test::circle_path(12, 1.0, 1.0));
  PlaceRecognizer places;  // online: trained at 4 and 8 keyframes
  for (int k = 0; k < 6; ++k) places.add(views[static_cast<size_t>(k)].features.descriptors);
  auto best = [&](size_t view) {
    const auto m = places.query(views[view].features.descriptors, 1, nullptr);
    return m.empty() ? -1 : m.front().entry;
  };
  ASSERT_EQ(best(3), 3) << "a keyframe's own view finds it";
  places.forget(3);
  EXPECT_NE(best(3), 3);
  for (int k = 6; k < 12; ++k) places.add(views[static_cast<size_t>(k)].features.descriptors);
  EXPECT_GE(places.trainings(), 2);
  EXPECT_EQ(places.size(), 12);
  EXPECT_NE(best(3), 3) << "retraining brought a forgotten keyframe back";
  EXPECT_EQ(best(10), 10) << "entries keep their numbers";
  EXPECT_EQ(best(4), 4);
}

TEST(PlaceRecognizer, FindsNoLoopOnALoopFreePath) {
  // Along a 12 m wall, looking at it from 1.5 m: each stretch of wall is seen once.
  const SyntheticRoom room(5, 7.0, 1.5, 2.5);
  const int n = 40;
  const auto views = views_along(room, test::straight_path(n, 12.0));
  PlaceRecognizer places;
  for (int k = 0; k < n; ++k) {
    const auto matches = places.query(views[k].features.descriptors, 15, [k](int e) { return e <= k - 20; });
    for (const BowMatch& m : matches) {
      const LoopConstraint c = verify_loop(views[k].features, views[m.entry].features, VerificationOptions{}, 1);
      EXPECT_FALSE(c.accepted) << "view " << k << " closed a loop with view " << m.entry;
    }
    places.add(views[k].features.descriptors);
  }
}

TEST(Vocabulary, TrainsSavesAndLoadsTheSameWords) {
  const SyntheticRoom room(5, 3.0, 2.5, 2.5);
  const auto views = views_along(room, test::circle_path(6, 1.0, 1.0));
  std::vector<cv::Mat> images;
  for (const auto& v : views) images.push_back(v.features.descriptors);
  const Vocabulary vocabulary = Vocabulary::train(images, VocabularyOptions{8, 3, 5}, 42);
  EXPECT_GT(vocabulary.num_words(), 100);
  kestrel::test::TempDir dir;
  const std::string path = (dir.path() / "words.voc").string();
  vocabulary.save(path);
  const Vocabulary loaded = Vocabulary::load(path);
  EXPECT_EQ(loaded.num_words(), vocabulary.num_words());
  EXPECT_EQ(loaded.words(images[3]), vocabulary.words(images[3]));
  const BowVector a = vocabulary.transform(images[2]);
  EXPECT_NEAR(bow_score(a, loaded.transform(images[2])), 1.0, 1e-12);
  EXPECT_LT(bow_score(a, vocabulary.transform(images[5])), 0.5) << "views of different walls";

  // Truncated, and not a vocabulary at all: errors naming the file.
  std::string bytes(std::filesystem::file_size(path), '\0');
  std::ifstream(path, std::ios::binary).read(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  const std::string truncated = (dir.path() / "truncated.voc").string();
  std::ofstream(truncated, std::ios::binary) << bytes.substr(0, bytes.size() / 2);
  const std::string text = (dir.path() / "text.voc").string();
  std::ofstream(text) << "hello\n";
  for (const std::string& bad : {truncated, text, (dir.path() / "missing.voc").string()}) {
    try {
      Vocabulary::load(bad);
      ADD_FAILURE() << bad << " loaded";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(bad), std::string::npos) << e.what();
    }
  }
}

TEST(TwoViewAdjustment, RecoversAnExactRelativePoseFromAPerturbedStart) {
  const PinholeCamera camera = test::test_camera();
  Eigen::Isometry3d T_a_b = se3::exp((Vector6d() << 0.3, -0.1, 0.2, 0.05, -0.2, 0.1).finished());
  std::vector<TwoViewObservation> observations;
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  while (observations.size() < 40) {
    const Eigen::Vector3d X_b(u(rng), 0.7 * u(rng), 3.0 + u(rng));
    const Eigen::Vector3d X_a = T_a_b * X_b;
    if (X_a.z() < 0.5) continue;
    const Eigen::Vector2d pa = camera.project(X_a), pb = camera.project(X_b);
    if (!camera.contains(pa.x(), pa.y()) || !camera.contains(pb.x(), pb.y())) continue;
    observations.push_back({pa, pb, X_a.z(), X_b.z()});
  }
  const Eigen::Isometry3d start = T_a_b * se3::exp((Vector6d() << 0.03, 0.02, -0.02, 0.01, 0.02, -0.01).finished());
  const TwoViewResult r = adjust_two_views(camera, camera, observations, start);
  ASSERT_TRUE(r.ok);
  expect_pose_near(r.T_a_b, T_a_b, 1e-6, 1e-7);
  EXPECT_LT(r.rms_px, 1e-6);
}

}  // namespace
}  // namespace kestrel::slam
