#include "slam/place/place_recognizer.h"

#include "slam/place/vocabulary_training.h"

#include <algorithm>
#include <cmath>
#include <random>

namespace kestrel::slam {

PlaceRecognizer::PlaceRecognizer(const PlaceOptions& options,
                                 std::shared_ptr<const Vocabulary> vocabulary)
    : options_(options), fixed_(std::move(vocabulary)), next_training_(options.online_first_training) {
  if (fixed_ && fixed_->empty()) throw std::invalid_argument("place recognition: empty vocabulary");
}

const Vocabulary* PlaceRecognizer::vocabulary() const {
  if (fixed_) return fixed_.get();
  return online_.empty() ? nullptr : &online_;
}

int PlaceRecognizer::num_words() const {
  const Vocabulary* v = vocabulary();
  return v ? v->num_words() : 0;
}

std::shared_ptr<const Vocabulary> PlaceRecognizer::vocabulary_in_use() const {
  return fixed_ ? fixed_ : std::make_shared<const Vocabulary>(online_);
}

int PlaceRecognizer::add(const cv::Mat& descriptors) {
  const int entry = entries_++;
  if (online()) descriptors_.push_back(descriptors.clone());
  if (online() && size() >= next_training_) {
    retrain();  // indexes every keyframe, this one included
    next_training_ = 2 * size();
  } else if (const Vocabulary* v = vocabulary()) {
    database_.add(v->transform(descriptors));
  }
  return entry;
}

void PlaceRecognizer::retrain() {
  // Training set: every kept keyframe's descriptors (a forgotten one has none), or a random
  // subset of them when there are too many.
  std::vector<cv::Mat> kept;
  size_t total = 0;
  for (const auto& d : descriptors_) {
    if (d.empty()) continue;
    kept.push_back(d);
    total += static_cast<size_t>(d.rows);
  }
  if (total == 0) return;  // nothing to learn words from yet (keyframes without texture)
  std::mt19937_64 rng(options_.seed + static_cast<uint64_t>(trainings_));
  const std::vector<cv::Mat> images = subsample_rows(kept, static_cast<size_t>(options_.online_max_training), rng);
  total = 0;
  for (const auto& d : images) total += static_cast<size_t>(d.rows);
  VocabularyOptions vo = options_.online_vocabulary;
  // About ten descriptors per word: k^L ~ total / 10.
  const double levels = std::log(std::max(static_cast<double>(total) / 10.0, 2.0)) / std::log(vo.branching);
  vo.depth = std::clamp(static_cast<int>(std::ceil(levels)), 1, options_.online_vocabulary.depth);
  online_ = Vocabulary::train(images, vo, rng());
  // idf from every kept keyframe, not the subset.
  std::vector<std::vector<int>> documents;
  for (const auto& d : kept) documents.push_back(online_.words(d));
  online_.set_idf(documents);
  // Every entry keeps its number; a forgotten one stays empty.
  database_.clear();
  for (const auto& d : descriptors_) database_.add(d.empty() ? BowVector{} : online_.transform(d));
  ++trainings_;
}

std::vector<BowMatch> PlaceRecognizer::query(const cv::Mat& descriptors, int max_results,
                                             const std::function<bool(int)>& allowed) const {
  const Vocabulary* v = vocabulary();
  if (!v || descriptors.empty()) return {};
  return database_.query(v->transform(descriptors), max_results, allowed);
}

double PlaceRecognizer::score(int a, int b) const {
  if (a >= database_.size() || b >= database_.size()) return 0.0;
  return bow_score(database_.vector(a), database_.vector(b));
}

void PlaceRecognizer::forget(int entry) {
  if (entry < 0 || entry >= entries_) return;
  if (online()) descriptors_[static_cast<size_t>(entry)] = cv::Mat();  // later trainings skip it
  database_.remove(entry);
}

void PlaceRecognizer::clear() {
  entries_ = 0;
  descriptors_.clear();
  database_.clear();
  online_ = Vocabulary();
  next_training_ = options_.online_first_training;
  trainings_ = 0;
}

}  // namespace kestrel::slam
