#pragma once
// Place recognition: which earlier keyframes look like this one. Each keyframe's ORB
// descriptors become a bag-of-words vector, indexed for retrieval (bow_database.h).
//
// Two vocabularies (slam/README.md says which is used and why):
//  * fixed: a vocabulary trained beforehand (Vocabulary::train) and loaded from a file;
//  * online: built from the keyframes seen so far — retrained, and every keyframe re-indexed,
//    each time their number doubles, so that the words fit the place being mapped; the cost
//    stays proportional to n log n over a run.
//
// Invariant: entry i of queries is the i-th keyframe added (0-based).

#include <functional>
#include <memory>
#include <vector>

#include "slam/place/bow_database.h"
#include "slam/place/vocabulary.h"

namespace kestrel::slam {

struct PlaceOptions {
  /// Shape of the online vocabulary; its depth grows with the data (about 10 descriptors per
  /// word) up to this.
  VocabularyOptions online_vocabulary{10, 5, 10};
  int online_first_training = 4;     ///< keyframes before the first vocabulary
  int online_max_training = 60000;   ///< descriptors at most per training (a random subset)
  uint64_t seed = 1;
};

class PlaceRecognizer {
 public:
  /// With `vocabulary` empty (nullptr), the online vocabulary.
  explicit PlaceRecognizer(const PlaceOptions& options = {},
                           std::shared_ptr<const Vocabulary> vocabulary = nullptr);

  bool online() const { return !fixed_; }
  /// Adds the next keyframe's descriptors (CV_8UC1 x 32); returns its entry number.
  int add(const cv::Mat& descriptors);
  /// The best `max_results` earlier keyframes that `allowed(entry)` accepts, best first.
  std::vector<BowMatch> query(const cv::Mat& descriptors, int max_results,
                              const std::function<bool(int)>& allowed) const;
  /// Similarity of two stored keyframes.
  double score(int a, int b) const;
  /// Stops returning `entry` (a keyframe that let its features go); its number stays taken.
  void forget(int entry);
  int size() const { return entries_; }
  /// Times the online vocabulary was (re)trained.
  int trainings() const { return trainings_; }
  /// Words of the vocabulary in use (0 before the first online training).
  int num_words() const;
  /// The vocabulary in use (the fixed one, or a copy of the online one; empty before the first
  /// online training): what indexes the keyframes, kept with a saved map.
  std::shared_ptr<const Vocabulary> vocabulary_in_use() const;
  void clear();

 private:
  const Vocabulary* vocabulary() const;
  void retrain();

  PlaceOptions options_;
  std::shared_ptr<const Vocabulary> fixed_;
  Vocabulary online_;
  int entries_ = 0;
  /// Online vocabulary only: each keyframe's descriptors, to train on and re-index after each
  /// training (a fixed vocabulary needs none: the keyframes' own are not copied).
  std::vector<cv::Mat> descriptors_;
  BowDatabase database_;
  int next_training_ = 0;
  int trainings_ = 0;
};

}  // namespace kestrel::slam
