// kestrel-slam-vocabulary: trains the place-recognition vocabulary (a tree of binary words)
// from the ORB descriptors of TUM RGB-D folders' colour images and writes it in the format
// `kestrel-slam --vocabulary FILE` reads. The training is in the library
// (slam/place/vocabulary_training.h); this is the file handling. See slam/README.md.

#include <spdlog/spdlog.h>

#include <filesystem>
#include <iostream>
#include <stdexcept>
#include <string>
#include <vector>

#include "common/cli.h"
#include "common/error.h"
#include "drivers/tum/tum_sequence.h"
#include "slam/place/vocabulary_training.h"

namespace {

using namespace kestrel;
using namespace kestrel::slam;

struct Options {
  std::vector<std::string> tum;
  std::string out;
  int every = 1;
  VocabularyTrainingOptions training;
};

int train(const Options& o) {
  VocabularyTrainer trainer(o.training);
  for (const std::string& folder : o.tum) {
    const tum::TumSequence sequence(folder);
    size_t images = 0, descriptors = 0;
    for (size_t i = 0; i < sequence.size(); i += static_cast<size_t>(o.every)) {
      descriptors += static_cast<size_t>(trainer.add_frame(sequence.frame(i)));
      ++images;
    }
    spdlog::info("{}: {} images, {} descriptors", folder, images, descriptors);
  }
  if (trainer.num_descriptors() == 0) throw InputError("no ORB features in the images of the given folders");
  const Vocabulary v = trainer.train();
  v.save(o.out);
  std::cout << "images: " << trainer.num_images() << ", descriptors: " << trainer.num_descriptors()
            << ", words: " << v.num_words() << " (k " << v.branching() << ", L " << v.depth() << ")\n"
            << o.out << ": " << std::filesystem::file_size(o.out) << " bytes\n";
  return kExitOk;
}

}  // namespace

int main(int argc, char** argv) {
  cli::App app("slam-vocabulary",
               "Trains kestrel-slam's place-recognition vocabulary from the colour images of TUM RGB-D "
               "folders (e.g. written by `kestrel sim --tum DIR`) and writes it for `kestrel-slam --vocabulary`.");
  Options o;
  app.add_option("--tum", o.tum, "TUM RGB-D folder to train on (repeat for several)")->required();
  app.add_option("--out", o.out, "Vocabulary file to write")->required();
  app.add_option("--every", o.every, "Use every n-th frame of each folder")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--branching", o.training.tree.branching, "k: children per node")
      ->check(CLI::Range(2, 64))->capture_default_str();
  app.add_option("--depth", o.training.tree.depth, "L: levels below the root (up to k^L words)")
      ->check(CLI::Range(1, 8))->capture_default_str();
  app.add_option("--iterations", o.training.tree.max_iterations, "k-majority iterations per node")
      ->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--max-descriptors", o.training.max_descriptors, "Descriptors clustered at most (a random subset)")
      ->check(CLI::Range(2, 100000000))->capture_default_str();
  app.add_option("--seed", o.training.seed, "Random seed (k-means++ seeding, subset)")->capture_default_str();
  return app.run(argc, argv, [&] { return train(o); });
}
