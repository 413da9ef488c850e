#include "slam/place/vocabulary_training.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace kestrel::slam {

std::vector<cv::Mat> subsample_rows(const std::vector<cv::Mat>& images, size_t max_rows, std::mt19937_64& rng) {
  size_t total = 0;
  for (const auto& d : images) total += static_cast<size_t>(d.rows);
  if (total <= max_rows) return images;
  const double keep = static_cast<double>(max_rows) / static_cast<double>(total);
  std::vector<cv::Mat> out;
  out.reserve(images.size());
  for (const cv::Mat& d : images) {
    std::vector<int> rows(static_cast<size_t>(d.rows));
    std::iota(rows.begin(), rows.end(), 0);
    std::shuffle(rows.begin(), rows.end(), rng);
    rows.resize(std::min(rows.size(), static_cast<size_t>(std::ceil(keep * d.rows))));
    cv::Mat subset(static_cast<int>(rows.size()), d.cols, d.type());
    for (size_t r = 0; r < rows.size(); ++r) d.row(rows[r]).copyTo(subset.row(static_cast<int>(r)));
    out.push_back(subset);
  }
  return out;
}

VocabularyTrainer::VocabularyTrainer(const VocabularyTrainingOptions& options)
    : options_(options), extractor_(options.features) {
  if (options.tree.branching < 2) throw std::invalid_argument("vocabulary training: branching must be >= 2");
  if (options.tree.depth < 1) throw std::invalid_argument("vocabulary training: depth must be >= 1");
  if (options.tree.max_iterations < 1) throw std::invalid_argument("vocabulary training: max_iterations must be >= 1");
  if (options.max_descriptors < 2) throw std::invalid_argument("vocabulary training: max_descriptors must be >= 2");
}

int VocabularyTrainer::add_descriptors(const cv::Mat& descriptors) {
  if (descriptors.empty()) {
    images_.emplace_back(0, 32, CV_8UC1);
    return 0;
  }
  if (descriptors.type() != CV_8UC1 || descriptors.cols != 32) {
    throw std::invalid_argument("vocabulary training: descriptors must be CV_8UC1 with 32 columns");
  }
  images_.push_back(descriptors.clone());
  rows_ += static_cast<size_t>(descriptors.rows);
  return descriptors.rows;
}

int VocabularyTrainer::add_image(const cv::Mat& grey) {
  if (grey.type() != CV_8UC1) throw std::invalid_argument("vocabulary training: the image must be grey (CV_8UC1)");
  return add_descriptors(extractor_.extract(grey, cv::Mat(), PinholeCamera{}).descriptors);
}

int VocabularyTrainer::add_frame(const RgbdFrame& frame) {
  if (frame.rgb.empty()) return add_descriptors(cv::Mat());
  cv::Mat grey;
  cv::cvtColor(frame.rgb, grey, cv::COLOR_RGB2GRAY);
  return add_image(grey);
}

Vocabulary VocabularyTrainer::train() const {
  if (rows_ == 0) throw std::invalid_argument("vocabulary training: no descriptors to train on");
  std::mt19937_64 rng(options_.seed);
  const std::vector<cv::Mat> subset = subsample_rows(images_, static_cast<size_t>(options_.max_descriptors), rng);
  Vocabulary v = Vocabulary::train(subset, options_.tree, rng());
  // idf over every training image with all its descriptors, not only the clustered subset.
  std::vector<std::vector<int>> documents;
  documents.reserve(images_.size());
  for (const cv::Mat& d : images_) documents.push_back(v.words(d));
  v.set_idf(documents);
  return v;
}

}  // namespace kestrel::slam
