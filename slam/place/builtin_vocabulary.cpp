#include "slam/place/builtin_vocabulary.h"

// The file's bytes, assembled into the object (GNU as .incbin); the build names the file in
// KESTREL_SLAM_VOCABULARY_FILE and rebuilds this object when it changes.
asm("  .section .rodata\n"
    "  .balign 16\n"
    "  .global kestrel_slam_builtin_vocabulary\n"
    "  .hidden kestrel_slam_builtin_vocabulary\n"
    "kestrel_slam_builtin_vocabulary:\n"
    "  .incbin \"" KESTREL_SLAM_VOCABULARY_FILE "\"\n"
    "  .global kestrel_slam_builtin_vocabulary_end\n"
    "  .hidden kestrel_slam_builtin_vocabulary_end\n"
    "kestrel_slam_builtin_vocabulary_end:\n"
    "  .previous\n");

extern "C" const char kestrel_slam_builtin_vocabulary[];
extern "C" const char kestrel_slam_builtin_vocabulary_end[];

namespace kestrel::slam {

std::shared_ptr<const Vocabulary> builtin_vocabulary() {
  static const std::shared_ptr<const Vocabulary> vocabulary = std::make_shared<const Vocabulary>(
      Vocabulary::load_from_memory(kestrel_slam_builtin_vocabulary,
                                   static_cast<size_t>(kestrel_slam_builtin_vocabulary_end - kestrel_slam_builtin_vocabulary),
                                   "built-in vocabulary"));
  return vocabulary;
}

}  // namespace kestrel::slam
