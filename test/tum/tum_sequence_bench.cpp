// Cost of reading TUM frames (PNG decoding and depth conversion) and of turning them into
// CAMERA_RGBD messages, per frame, on the real fr1_xyz sequence. Run: ./kestrel bench Tum
// (Release). Skips when ../shared/data is absent.

#include <benchmark/benchmark.h>

#include <filesystem>
#include <optional>

#include "common/transport/message.h"
#include "common/transport/rgbd_codec.h"
#include "drivers/tum/tum_sequence.h"

namespace {

using kestrel::tum::TumSequence;

const TumSequence* sequence() {
  static const std::optional<TumSequence> s = []() -> std::optional<TumSequence> {
    const std::filesystem::path p = std::filesystem::path(KESTREL_SHARED_DATA) / "tum/rgbd_dataset_freiburg1_xyz";
    std::error_code ec;
    if (!std::filesystem::is_regular_file(p / "rgb.txt", ec)) return std::nullopt;
    return TumSequence(p.string());
  }();
  return s ? &*s : nullptr;
}

void BM_TumFrameDecode(benchmark::State& state) {
  const TumSequence* s = sequence();
  if (!s) {
    state.SkipWithError("../shared/data/tum/rgbd_dataset_freiburg1_xyz is absent");
    return;
  }
  size_t i = 0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(s->frame(i));
    i = (i + 1) % s->size();
  }
}
BENCHMARK(BM_TumFrameDecode)->Unit(benchmark::kMillisecond);

// Encoding only (the frame is decoded once): raw, JPEG colour, zstd depth.
void BM_TumFrameEncode(benchmark::State& state) {
  const TumSequence* s = sequence();
  if (!s) {
    state.SkipWithError("../shared/data/tum/rgbd_dataset_freiburg1_xyz is absent");
    return;
  }
  const kestrel::RgbdFrame frame = s->frame(0);
  kestrel::transport::RgbdEncoding e;
  if (state.range(0) == 1) e.rgb = kestrel::rgbd_frame_t::RGB_JPEG;
  if (state.range(0) == 2) e.depth = kestrel::rgbd_frame_t::DEPTH_U16_MM_ZSTD;
  size_t bytes = 0;
  for (auto _ : state) {
    const auto m = kestrel::transport::encode_message(kestrel::transport::encode_rgbd(frame, e));
    bytes = m.size();
    benchmark::DoNotOptimize(m.data());
  }
  state.counters["message_kB"] = static_cast<double>(bytes) / 1e3;
}
BENCHMARK(BM_TumFrameEncode)->Arg(0)->Arg(1)->Arg(2)->ArgNames({"raw0_jpeg1_zstd2"})->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
