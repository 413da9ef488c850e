#pragma once
// Offline training of a vocabulary (vocabulary.h) from images, as `kestrel-slam-vocabulary`
// runs it: every training image gives its ORB descriptors (the same extractor SLAM's keyframes
// use, frame_features.h); the tree is clustered on all of them, or on a random subset when
// there are more than max_descriptors, and the idf weights come from every image.
//
// Invariant: image_descriptors() holds one CV_8UC1 x 32 matrix per image added, in order.

#include <cstdint>
#include <random>
#include <vector>

#include "common/rgbd_frame.h"
#include "slam/place/frame_features.h"
#include "slam/place/vocabulary.h"

namespace kestrel::slam {

struct VocabularyTrainingOptions {
  VocabularyOptions tree{8, 4, 10};   ///< k, L, k-majority iterations (the shipped file's)
  FeatureOptions features;            ///< as the keyframes' (SlamOptions::features)
  int max_descriptors = 200000;       ///< clustered at most (a random subset of the images' rows)
  uint64_t seed = 1;
};

/// A random subset of the rows of `images`, about `max_rows` in all, taken evenly from every
/// image (the same share of each); `images` unchanged when they hold no more than that.
std::vector<cv::Mat> subsample_rows(const std::vector<cv::Mat>& images, size_t max_rows, std::mt19937_64& rng);

class VocabularyTrainer {
 public:
  /// Throws std::invalid_argument naming an unusable option.
  explicit VocabularyTrainer(const VocabularyTrainingOptions& options = {});

  /// Adds one training image by its descriptors (CV_8UC1, 32 bytes a row; may be empty).
  /// Throws std::invalid_argument for another type or width. Returns the rows added.
  int add_descriptors(const cv::Mat& descriptors);
  /// Adds a grey (CV_8UC1) image by its ORB descriptors; returns their number.
  int add_image(const cv::Mat& grey);
  /// Adds an RGB-D frame's colour image (depth is not needed); returns the descriptors.
  int add_frame(const RgbdFrame& frame);

  size_t num_images() const { return images_.size(); }
  size_t num_descriptors() const { return rows_; }
  const std::vector<cv::Mat>& image_descriptors() const { return images_; }

  /// The vocabulary: clustered on (a subset of) the descriptors, idf over every image. Throws
  /// std::invalid_argument when no image gave a descriptor.
  Vocabulary train() const;

 private:
  VocabularyTrainingOptions options_;
  FeatureExtractor extractor_;
  std::vector<cv::Mat> images_;
  size_t rows_ = 0;
};

}  // namespace kestrel::slam
