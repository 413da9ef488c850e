#include "slam/place/vocabulary.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include "common/atomic_file.h"
#include "common/error.h"

namespace kestrel::slam {
namespace {

constexpr char kMagic[] = "KESTREL-VOCABULARY 1\n";

// k-means++ seeding on the Hamming distance: far-apart descriptors make better first centres.
std::vector<Descriptor> seed_centres(const std::vector<Descriptor>& all, const std::vector<int>& members,
                                     int k, std::mt19937_64& rng) {
  std::vector<Descriptor> centres;
  std::uniform_int_distribution<size_t> pick(0, members.size() - 1);
  centres.push_back(all[members[pick(rng)]]);
  std::vector<double> d2(members.size(), std::numeric_limits<double>::infinity());
  while (static_cast<int>(centres.size()) < k) {
    double total = 0.0;
    for (size_t i = 0; i < members.size(); ++i) {
      const double d = hamming(all[members[i]], centres.back());
      d2[i] = std::min(d2[i], d * d);
      total += d2[i];
    }
    if (!(total > 0.0)) break;  // every member equals a centre already
    std::uniform_real_distribution<double> u(0.0, total);
    double target = u(rng);
    size_t chosen = members.size() - 1;
    for (size_t i = 0; i < members.size(); ++i) {
      target -= d2[i];
      if (target <= 0.0) {
        chosen = i;
        break;
      }
    }
    centres.push_back(all[members[chosen]]);
  }
  return centres;
}

int nearest(const std::vector<Descriptor>& centres, const Descriptor& d) {
  int best = 0, best_distance = std::numeric_limits<int>::max();
  for (size_t c = 0; c < centres.size(); ++c) {
    const int h = hamming(centres[c], d);
    if (h < best_distance) {
      best_distance = h;
      best = static_cast<int>(c);
    }
  }
  return best;
}

}  // namespace

double bow_score(const BowVector& a, const BowVector& b) {
  // For non-negative L1-normalised vectors 1 - |a - b|_1 / 2 = sum over shared words of min.
  double score = 0.0;
  auto i = a.begin(), j = b.begin();
  while (i != a.end() && j != b.end()) {
    if (i->first < j->first) {
      ++i;
    } else if (j->first < i->first) {
      ++j;
    } else {
      score += std::min(i->second, j->second);
      ++i;
      ++j;
    }
  }
  return score;
}

Vocabulary Vocabulary::train(const std::vector<cv::Mat>& images, const VocabularyOptions& options,
                             uint64_t seed) {
  if (options.branching < 2 || options.depth < 1 || options.max_iterations < 1) {
    throw std::invalid_argument("vocabulary: need branching >= 2, depth >= 1, max_iterations >= 1");
  }
  std::vector<Descriptor> all;
  std::vector<std::pair<size_t, size_t>> ranges;  // per image: [begin, end) in all
  for (const cv::Mat& image : images) {
    const auto d = to_descriptors(image);
    ranges.emplace_back(all.size(), all.size() + d.size());
    all.insert(all.end(), d.begin(), d.end());
  }
  if (all.empty()) throw std::invalid_argument("vocabulary: no descriptors to train on");
  Vocabulary v;
  v.branching_ = options.branching;
  v.depth_ = options.depth;
  v.nodes_.push_back(Node{});
  std::vector<int> members(all.size());
  for (size_t i = 0; i < all.size(); ++i) members[i] = static_cast<int>(i);
  std::mt19937_64 rng(seed);
  v.build(0, members, 0, all, options, rng);

  std::vector<std::vector<int>> documents;
  for (const auto& [begin, end] : ranges) {
    std::vector<int> words;
    for (size_t i = begin; i < end; ++i) words.push_back(v.word(all[i]));
    documents.push_back(std::move(words));
  }
  v.set_idf(documents);
  return v;
}

void Vocabulary::build(int node, const std::vector<int>& members, int level,
                       const std::vector<Descriptor>& all, const VocabularyOptions& options,
                       std::mt19937_64& rng) {
  if (level == options.depth || static_cast<int>(members.size()) <= 1) {
    nodes_[node].word = static_cast<int>(words_.size());
    words_.push_back(node);
    return;
  }
  const int k = std::min<int>(options.branching, static_cast<int>(members.size()));
  std::vector<Descriptor> centres = seed_centres(all, members, k, rng);
  std::vector<int> assignment(members.size(), -1);
  for (int iteration = 0; iteration < options.max_iterations; ++iteration) {
    bool changed = false;
    for (size_t i = 0; i < members.size(); ++i) {
      const int c = nearest(centres, all[members[i]]);
      changed |= c != assignment[i];
      assignment[i] = c;
    }
    if (!changed) break;
    std::vector<std::vector<int>> clusters(centres.size());
    for (size_t i = 0; i < members.size(); ++i) clusters[assignment[i]].push_back(members[i]);
    for (size_t c = 0; c < centres.size(); ++c) {
      if (!clusters[c].empty()) centres[c] = majority(all, clusters[c]);
    }
  }
  std::vector<std::vector<int>> clusters(centres.size());
  for (size_t i = 0; i < members.size(); ++i) clusters[assignment[i]].push_back(members[i]);
  clusters.erase(std::remove_if(clusters.begin(), clusters.end(),
                                [](const std::vector<int>& c) { return c.empty(); }),
                 clusters.end());
  if (clusters.size() == 1) {  // indistinguishable members: one word
    nodes_[node].word = static_cast<int>(words_.size());
    words_.push_back(node);
    return;
  }
  const int first = static_cast<int>(nodes_.size());
  nodes_[node].first_child = first;
  nodes_[node].num_children = static_cast<int>(clusters.size());
  for (size_t c = 0; c < clusters.size(); ++c) {
    Node child;
    child.centre = majority(all, clusters[c]);
    nodes_.push_back(child);
  }
  for (size_t c = 0; c < clusters.size(); ++c) {
    build(first + static_cast<int>(c), clusters[c], level + 1, all, options, rng);
  }
}

int Vocabulary::word(const Descriptor& d) const {
  int node = 0;
  while (nodes_[node].word < 0) {
    const Node& n = nodes_[node];
    int best = n.first_child, best_distance = std::numeric_limits<int>::max();
    for (int c = n.first_child; c < n.first_child + n.num_children; ++c) {
      const int h = hamming(nodes_[c].centre, d);
      if (h < best_distance) {
        best_distance = h;
        best = c;
      }
    }
    node = best;
  }
  return nodes_[node].word;
}

std::vector<int> Vocabulary::words(const cv::Mat& descriptors) const {
  std::vector<int> out;
  for (const Descriptor& d : to_descriptors(descriptors)) out.push_back(word(d));
  return out;
}

BowVector Vocabulary::transform(const cv::Mat& descriptors) const {
  std::map<int, int> counts;
  const auto ws = words(descriptors);
  for (const int w : ws) ++counts[w];
  BowVector v;
  double total = 0.0;
  for (const auto& [w, n] : counts) {
    const double weight = static_cast<double>(n) / static_cast<double>(ws.size()) * idf_[w];
    if (weight > 0.0) {
      v.emplace_back(w, weight);
      total += weight;
    }
  }
  for (auto& [w, weight] : v) weight /= total;
  return v;
}

void Vocabulary::set_idf(const std::vector<std::vector<int>>& documents) {
  std::vector<int> containing(words_.size(), 0);
  for (const auto& doc : documents) {
    std::vector<int> unique = doc;
    std::sort(unique.begin(), unique.end());
    unique.erase(std::unique(unique.begin(), unique.end()), unique.end());
    for (const int w : unique) ++containing[w];
  }
  const double n = static_cast<double>(std::max<size_t>(documents.size(), 1));
  idf_.assign(words_.size(), 0.0);
  for (size_t w = 0; w < words_.size(); ++w) {
    // A word no document has seen is as informative as the rarest one.
    idf_[w] = std::log(n / std::max(containing[w], 1));
  }
}

void Vocabulary::save(const std::string& path) const {
  AtomicFile file(path);  // a failed run leaves no cut vocabulary that looks whole
  write(file.stream());
  file.commit();
}

void Vocabulary::write(std::ostream& out) const {
  out.write(kMagic, sizeof(kMagic) - 1);
  const int32_t header[4] = {branching_, depth_, static_cast<int32_t>(nodes_.size()),
                             static_cast<int32_t>(words_.size())};
  out.write(reinterpret_cast<const char*>(header), sizeof(header));
  for (const Node& n : nodes_) {
    out.write(reinterpret_cast<const char*>(n.centre.data()), sizeof(Descriptor));
    const int32_t fields[3] = {n.first_child, n.num_children, n.word};
    out.write(reinterpret_cast<const char*>(fields), sizeof(fields));
  }
  out.write(reinterpret_cast<const char*>(idf_.data()), static_cast<std::streamsize>(idf_.size() * sizeof(double)));
}

Vocabulary Vocabulary::load(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path + ": cannot open");
  return read(in, path);
}

Vocabulary Vocabulary::load_from_memory(const void* data, size_t size, const std::string& name) {
  std::istringstream in(std::string(static_cast<const char*>(data), size), std::ios::binary);
  return read(in, name);
}

Vocabulary Vocabulary::read(std::istream& in, const std::string& path) {
  auto corrupt = [&path](const std::string& what) { return InputError(path + ": not a vocabulary file (" + what + ")"); };
  char magic[sizeof(kMagic) - 1];
  if (!in.read(magic, sizeof(magic)) || std::string(magic, sizeof(magic)) != std::string(kMagic, sizeof(kMagic) - 1)) {
    throw corrupt("bad header");
  }
  int32_t header[4];
  if (!in.read(reinterpret_cast<char*>(header), sizeof(header))) throw corrupt("truncated header");
  Vocabulary v;
  v.branching_ = header[0];
  v.depth_ = header[1];
  const int32_t num_nodes = header[2], num_words = header[3];
  if (v.branching_ < 2 || v.depth_ < 1 || num_nodes < 1 || num_words < 1 || num_words > num_nodes ||
      num_nodes > 50'000'000) {
    throw corrupt("impossible sizes");
  }
  // Nothing is sized beyond what the stream still holds (a node is 44 bytes): a damaged or
  // hostile count is an error, not an allocation.
  const std::streampos here = in.tellg();
  in.seekg(0, std::ios::end);
  const std::streamoff left = in.tellg() - here;
  in.seekg(here);
  if (!in || left < static_cast<std::streamoff>(num_nodes) * static_cast<std::streamoff>(sizeof(Descriptor) + 12)) {
    throw corrupt("shorter than its " + std::to_string(num_nodes) + " nodes");
  }
  v.nodes_.resize(static_cast<size_t>(num_nodes));
  v.words_.assign(static_cast<size_t>(num_words), -1);
  for (int32_t i = 0; i < num_nodes; ++i) {
    Node& n = v.nodes_[i];
    int32_t fields[3];
    if (!in.read(reinterpret_cast<char*>(n.centre.data()), sizeof(Descriptor)) ||
        !in.read(reinterpret_cast<char*>(fields), sizeof(fields))) {
      throw corrupt("truncated at node " + std::to_string(i));
    }
    n.first_child = fields[0];
    n.num_children = fields[1];
    n.word = fields[2];
    const bool leaf = n.word >= 0;
    // In 64 bits: first_child + num_children must not wrap around.
    const bool children_ok = n.num_children >= 1 && n.num_children <= v.branching_ && n.first_child > i &&
                             static_cast<int64_t>(n.first_child) + n.num_children <= num_nodes;
    if (leaf ? (n.word >= num_words || v.words_[n.word] >= 0) : !children_ok) {
      throw corrupt("bad node " + std::to_string(i));
    }
    if (leaf) v.words_[n.word] = i;
  }
  v.idf_.resize(static_cast<size_t>(num_words));
  if (!in.read(reinterpret_cast<char*>(v.idf_.data()), static_cast<std::streamsize>(v.idf_.size() * sizeof(double)))) {
    throw corrupt("truncated weights");
  }
  if (in.peek() != std::char_traits<char>::eof()) throw corrupt("trailing bytes");
  for (int32_t w = 0; w < num_words; ++w) {
    if (v.words_[w] < 0 || !(v.idf_[w] >= 0.0) || !std::isfinite(v.idf_[w])) throw corrupt("bad word " + std::to_string(w));
  }
  return v;
}

}  // namespace kestrel::slam
