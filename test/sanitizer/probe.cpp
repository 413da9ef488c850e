// A program with one defect per sanitizer, chosen by its argument, so that the sanitizer
// harness test (harness_test.cpp) can check that a child's report reaches the test. Built only
// in the sanitizer builds; every defect is there on purpose.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <thread>

namespace {

// volatile: the compiler must not prove the defects away.
volatile int g_index = 8;
volatile int g_big = std::numeric_limits<int>::max();

int heap_overflow() {
  int* a = new int[8];
  std::memset(a, 0, 8 * sizeof(int));
  const int v = a[g_index];  // one past the end
  delete[] a;
  return v;
}

int signed_overflow() { return g_big + 1; }

int leak() {
  int* p = new int[100];
  p[0] = 1;
  p = nullptr;  // the only pointer to it is gone: LeakSanitizer reports it at exit
  return 0;
}

int data_race() {
  int shared = 0;
  std::thread t([&shared] { shared = 1; });
  shared = 2;  // no ordering with the thread's write
  t.join();
  return shared == 0 ? 1 : 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 2 && std::strcmp(argv[1], "heap-overflow") == 0) return heap_overflow() == 12345 ? 10 : 0;
  if (argc == 2 && std::strcmp(argv[1], "signed-overflow") == 0) return signed_overflow() == 0 ? 10 : 0;
  if (argc == 2 && std::strcmp(argv[1], "leak") == 0) return leak();
  if (argc == 2 && std::strcmp(argv[1], "data-race") == 0) return data_race();
  if (argc == 2 && std::strcmp(argv[1], "clean") == 0) return 0;
  std::fprintf(stderr, "usage: kestrel_sanitizer_probe heap-overflow|signed-overflow|leak|data-race|clean\n");
  return 2;
}
