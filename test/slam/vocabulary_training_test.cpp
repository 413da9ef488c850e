// Offline vocabulary training (slam/place/vocabulary_training.h) on descriptors whose clusters
// are known: copies of the same centre fall into one word and different centres into different
// words, the idf weights count the training images, the file round-trips, and bad input is
// refused.

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

#include "common/error.h"
#include "slam/place/builtin_vocabulary.h"
#include "slam/place/vocabulary_training.h"
#include "test/support/test_support.h"

namespace kestrel::slam {
namespace {

constexpr int kCentres = 8;
constexpr int kCopies = 10;
constexpr int kImages = 4;

std::vector<Descriptor> random_centres(std::mt19937_64& rng) {
  std::vector<Descriptor> c(kCentres);
  for (auto& d : c)
    for (auto& w : d) w = rng();
  return c;
}

// A copy of `centre` with up to 3 random bits flipped (the centres are ~128 bits apart).
Descriptor noisy(const Descriptor& centre, std::mt19937_64& rng) {
  Descriptor d = centre;
  std::uniform_int_distribution<int> bit(0, 255), flips(0, 3);
  for (int n = flips(rng); n > 0; --n) {
    const int b = bit(rng);
    d[static_cast<size_t>(b / 64)] ^= uint64_t{1} << (b % 64);
  }
  return d;
}

cv::Mat to_mat(const std::vector<Descriptor>& ds) {
  cv::Mat m(static_cast<int>(ds.size()), 32, CV_8UC1);
  for (size_t i = 0; i < ds.size(); ++i) std::memcpy(m.ptr<uint8_t>(static_cast<int>(i)), ds[i].data(), 32);
  return m;
}

// Image j holds kCopies noisy copies of centres 0..6; image 0 also of centre 7.
struct KnownImages {
  std::vector<Descriptor> centres;
  std::vector<cv::Mat> images;
  std::vector<std::vector<int>> centre_of_row;  // per image
};

KnownImages known_images(uint64_t seed) {
  std::mt19937_64 rng(seed);
  KnownImages k;
  k.centres = random_centres(rng);
  for (int j = 0; j < kImages; ++j) {
    std::vector<Descriptor> rows;
    std::vector<int> centre;
    for (int c = 0; c < kCentres; ++c) {
      if (c == kCentres - 1 && j != 0) continue;
      for (int n = 0; n < kCopies; ++n) {
        rows.push_back(noisy(k.centres[static_cast<size_t>(c)], rng));
        centre.push_back(c);
      }
    }
    k.images.push_back(to_mat(rows));
    k.centre_of_row.push_back(centre);
  }
  return k;
}

VocabularyTrainingOptions one_level() {
  VocabularyTrainingOptions o;
  o.tree = {kCentres, 1, 10};
  return o;
}

// Every row's word, per image.
std::vector<std::vector<int>> words_of(const Vocabulary& v, const KnownImages& k) {
  std::vector<std::vector<int>> out;
  for (const auto& image : k.images) out.push_back(v.words(image));
  return out;
}

TEST(VocabularyTraining, EachKnownClusterIsOneWord) {
  const KnownImages k = known_images(3);
  VocabularyTrainer trainer(one_level());
  for (const auto& image : k.images) trainer.add_descriptors(image);
  EXPECT_EQ(trainer.num_images(), static_cast<size_t>(kImages));
  EXPECT_EQ(trainer.num_descriptors(), static_cast<size_t>((kImages * (kCentres - 1) + 1) * kCopies));
  const Vocabulary v = trainer.train();
  ASSERT_EQ(v.num_words(), kCentres);
  std::vector<int> word_of_centre(kCentres, -1);
  const auto words = words_of(v, k);
  for (size_t j = 0; j < words.size(); ++j) {
    for (size_t r = 0; r < words[j].size(); ++r) {
      int& w = word_of_centre[static_cast<size_t>(k.centre_of_row[j][r])];
      if (w < 0) w = words[j][r];
      EXPECT_EQ(words[j][r], w) << "image " << j << " row " << r;
    }
  }
  EXPECT_EQ(std::set<int>(word_of_centre.begin(), word_of_centre.end()).size(), static_cast<size_t>(kCentres));
  // The centres themselves fall in their clusters' words.
  for (int c = 0; c < kCentres; ++c) EXPECT_EQ(v.word(k.centres[static_cast<size_t>(c)]), word_of_centre[c]);
  // idf = log(N / images containing the word): centre 0 is in all 4 images, centre 7 in one.
  EXPECT_NEAR(v.idf(word_of_centre[0]), 0.0, 1e-12);
  EXPECT_NEAR(v.idf(word_of_centre[kCentres - 1]), std::log(4.0), 1e-12);
}

TEST(VocabularyTraining, ASubsetStillSeparatesTheClustersAndIsReproducible) {
  const KnownImages k = known_images(5);
  VocabularyTrainingOptions o;
  o.tree = {4, 2, 10};       // up to 16 words for 8 clusters
  o.max_descriptors = 120;   // of 290
  auto train = [&] {
    VocabularyTrainer trainer(o);
    for (const auto& image : k.images) trainer.add_descriptors(image);
    return trainer.train();
  };
  const Vocabulary a = train(), b = train();
  const auto wa = words_of(a, k), wb = words_of(b, k);
  EXPECT_EQ(wa, wb) << "same seed, same vocabulary";
  // Different centres never share a word (a centre may be split over several).
  std::vector<std::set<int>> words_of_centre(kCentres);
  for (size_t j = 0; j < wa.size(); ++j)
    for (size_t r = 0; r < wa[j].size(); ++r) words_of_centre[static_cast<size_t>(k.centre_of_row[j][r])].insert(wa[j][r]);
  for (int c = 0; c < kCentres; ++c)
    for (int d = c + 1; d < kCentres; ++d)
      for (const int w : words_of_centre[static_cast<size_t>(c)]) EXPECT_EQ(words_of_centre[static_cast<size_t>(d)].count(w), 0u);
}

TEST(VocabularyTraining, TheSavedFileGivesTheSameWordsAndVectors) {
  const KnownImages k = known_images(7);
  VocabularyTrainingOptions o;
  o.tree = {3, 3, 10};
  VocabularyTrainer trainer(o);
  for (const auto& image : k.images) trainer.add_descriptors(image);
  const Vocabulary v = trainer.train();
  test::TempDir dir;
  const std::string path = (dir / "trained.voc").string();
  v.save(path);
  const Vocabulary loaded = Vocabulary::load(path);
  EXPECT_EQ(loaded.num_words(), v.num_words());
  EXPECT_EQ(loaded.branching(), 3);
  EXPECT_EQ(loaded.depth(), 3);
  EXPECT_EQ(words_of(loaded, k), words_of(v, k));
  for (const auto& image : k.images) EXPECT_EQ(loaded.transform(image), v.transform(image));
}

TEST(VocabularyTraining, ImagesGiveTheirOrbDescriptors) {
  cv::Mat grey(240, 320, CV_8UC1);
  cv::RNG rng(11);
  // Random 8x8 blocks: plenty of corners.
  for (int r = 0; r < grey.rows; r += 8)
    for (int c = 0; c < grey.cols; c += 8) grey(cv::Rect(c, r, 8, 8)).setTo(rng.uniform(0, 256));
  VocabularyTrainer trainer;
  EXPECT_GT(trainer.add_image(grey), 100);
  EXPECT_EQ(trainer.add_image(cv::Mat(240, 320, CV_8UC1, cv::Scalar(128))), 0) << "a blank image has none";
  RgbdFrame no_colour;
  EXPECT_EQ(trainer.add_frame(no_colour), 0);
  EXPECT_EQ(trainer.num_images(), 3u);
  EXPECT_EQ(trainer.image_descriptors()[1].rows, 0);
}

TEST(VocabularyTraining, BadInputIsRefused) {
  VocabularyTrainer trainer;
  EXPECT_THROW(trainer.train(), std::invalid_argument) << "nothing to train on";
  trainer.add_descriptors(cv::Mat(0, 32, CV_8UC1));
  EXPECT_THROW(trainer.train(), std::invalid_argument) << "only empty images";
  EXPECT_THROW(trainer.add_descriptors(cv::Mat(3, 32, CV_32FC1, cv::Scalar(0))), std::invalid_argument);
  EXPECT_THROW(trainer.add_descriptors(cv::Mat(3, 16, CV_8UC1, cv::Scalar(0))), std::invalid_argument);
  EXPECT_THROW(trainer.add_image(cv::Mat(10, 10, CV_8UC3, cv::Scalar(0, 0, 0))), std::invalid_argument);
  VocabularyTrainingOptions bad;
  bad.tree.branching = 1;
  EXPECT_THROW(VocabularyTrainer{bad}, std::invalid_argument);
  bad = {};
  bad.tree.depth = 0;
  EXPECT_THROW(VocabularyTrainer{bad}, std::invalid_argument);
  bad = {};
  bad.max_descriptors = 1;
  EXPECT_THROW(VocabularyTrainer{bad}, std::invalid_argument);
}

TEST(BuiltinVocabulary, IsTheShippedFile) {
  const auto builtin = builtin_vocabulary();
  ASSERT_TRUE(builtin);
  EXPECT_EQ(builtin, builtin_vocabulary()) << "decoded once";
  EXPECT_EQ(builtin->branching(), 8);
  EXPECT_EQ(builtin->depth(), 4);
  EXPECT_EQ(builtin->num_words(), 4096);
  const Vocabulary file = Vocabulary::load(std::string(KESTREL_SOURCE_DIR) + "/slam/vocabulary/sim_k8l4.voc");
  const KnownImages k = known_images(9);
  for (const auto& image : k.images) {
    EXPECT_EQ(builtin->words(image), file.words(image));
    EXPECT_EQ(builtin->transform(image), file.transform(image));
  }
}

TEST(BuiltinVocabulary, CorruptMemoryIsRefusedNamingIt) {
  const std::string bytes = "KESTREL-VOCABULARY 1\n\x01\x02";
  try {
    Vocabulary::load_from_memory(bytes.data(), bytes.size(), "test bytes");
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("test bytes: not a vocabulary file"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace kestrel::slam
