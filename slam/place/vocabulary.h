#pragma once
// A vocabulary tree of binary words (Nister & Stewenius 2006; Galvez-Lopez & Tardos 2012):
// descriptors are quantised by descending a tree built by hierarchical k-majority clustering;
// the leaves are the words. An image becomes a bag-of-words vector of tf-idf weights.
//
// Invariants: node 0 is the root; every inner node has 1..branching children; every leaf is a
// word with an id in [0, num_words()); a word's idf weight is >= 0. transform() gives a vector
// sorted by word id with weights summing to 1 (or empty).

#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "slam/place/binary_descriptor.h"

namespace kestrel::slam {

/// Sparse bag-of-words vector: (word id, weight), sorted by word id.
using BowVector = std::vector<std::pair<int, double>>;

/// Similarity of two L1-normalised vectors, 1 - |a - b|_1 / 2, in [0, 1].
double bow_score(const BowVector& a, const BowVector& b);

struct VocabularyOptions {
  int branching = 10;      ///< k: children per node
  int depth = 4;           ///< L: levels below the root (up to k^L words)
  int max_iterations = 10; ///< k-majority iterations per node
};

class Vocabulary {
 public:
  Vocabulary() = default;

  /// Trains on the descriptors of `images` (one entry per image, CV_8UC1 x 32 bytes); the
  /// idf weights come from the same images. `seed` makes it reproducible.
  static Vocabulary train(const std::vector<cv::Mat>& images, const VocabularyOptions& options,
                          uint64_t seed);

  bool empty() const { return nodes_.empty(); }
  int num_words() const { return static_cast<int>(words_.size()); }
  int branching() const { return branching_; }
  int depth() const { return depth_; }

  /// The word a descriptor falls into (the vocabulary must not be empty).
  int word(const Descriptor& d) const;
  /// The tf-idf bag of words of an image's descriptors.
  BowVector transform(const cv::Mat& descriptors) const;
  /// Words of the rows of `descriptors`, in order.
  std::vector<int> words(const cv::Mat& descriptors) const;

  /// Replaces the idf weights with log(N / n_w) over `documents` (each a list of word ids).
  void set_idf(const std::vector<std::vector<int>>& documents);
  double idf(int word) const { return idf_[word]; }

  /// Binary file "KESTREL-VOCABULARY 1"; throws InputError naming the file when it cannot be
  /// written, or read back (missing, truncated, corrupt).
  void save(const std::string& path) const;
  static Vocabulary load(const std::string& path);
  /// The same format from memory (e.g. a file built into the program); errors name `name`.
  static Vocabulary load_from_memory(const void* data, size_t size, const std::string& name);
  /// The same format on a stream (a section of a saved SLAM map); read() takes the whole
  /// rest of the stream, errors name `name`.
  void write(std::ostream& out) const;
  static Vocabulary read(std::istream& in, const std::string& name);

 private:
  struct Node {
    Descriptor centre{};
    int first_child = -1;  ///< children are consecutive nodes
    int num_children = 0;
    int word = -1;         ///< leaf: its word id
  };
  void build(int node, const std::vector<int>& members, int level,
             const std::vector<Descriptor>& all, const VocabularyOptions& options,
             std::mt19937_64& rng);

  int branching_ = 0;
  int depth_ = 0;
  std::vector<Node> nodes_;
  std::vector<int> words_;  ///< word id -> node
  std::vector<double> idf_;
};

}  // namespace kestrel::slam
