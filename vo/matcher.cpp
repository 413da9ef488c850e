#include "vo/matcher.h"

#include <cmath>
#include <limits>

#include "sensors/depth_image.h"
#include "vo/subpixel.h"

namespace kestrel::vo {

void Matcher::match(const Frame& ref, const Frame& cur, const std::vector<Eigen::Vector2f>& predicted,
                    const sensors::Lens& lens, const MatchOptions& options, std::vector<Match>& matches) {
  matches.clear();
  const size_t n_ref = ref.features.size(), n_cur = cur.features.size();
  constexpr int kNone = std::numeric_limits<int>::max();
  best_cur_.assign(n_ref, -1);
  best_cur_sad_.assign(n_ref, kNone);
  best_ref_.assign(n_cur, -1);
  best_ref_sad_.assign(n_cur, kNone);
  const int bytes = ref.descriptors.bytes();
  const int pixels = std::min(options.window_size * options.window_size, bytes);
  const int max_sad = options.max_sad_per_pixel * pixels;

  for (size_t i = 0; i < n_ref; ++i) {
    const Eigen::Vector2f& p0 = predicted[i];
    if (!p0.allFinite()) continue;
    const Feature& fr = ref.features[i];
    const int level = fr.level;
    if (level >= cur.pyramid.levels()) continue;
    const float radius = static_cast<float>(options.search_radius_px) / float(1 << level);
    const uint8_t* d_ref = ref.descriptors[static_cast<int>(i)];
    int& bc = best_cur_[i];
    int& bs = best_cur_sad_[i];
    cur.grids[static_cast<size_t>(level)].for_each_within(
        from_level0(p0.x(), level), from_level0(p0.y(), level), radius, [&](int j) {
          const int s = sad(d_ref, cur.descriptors[j], bytes);
          if (s < bs) {
            bs = s;
            bc = j;
          }
          const size_t js = static_cast<size_t>(j);
          if (s < best_ref_sad_[js]) {
            best_ref_sad_[js] = s;
            best_ref_[js] = static_cast<int>(i);
          }
        });
  }

  for (size_t i = 0; i < n_ref; ++i) {
    const int j = best_cur_[i];
    if (j < 0 || best_cur_sad_[i] > max_sad) continue;
    if (best_ref_[static_cast<size_t>(j)] != static_cast<int>(i)) continue;
    const Feature& fr = ref.features[i];
    const Feature& fc = cur.features[static_cast<size_t>(j)];
    Match m;
    m.ref = static_cast<int>(i);
    m.cur = j;
    m.sad = best_cur_sad_[i];
    m.cur_ideal = fc.ideal;
    m.cur_point = fc.p_camera;
    if (options.subpixel) {
      const SubpixelResult r = refine_subpixel(
          ref.pyramid.level(fr.level), Eigen::Vector2i(int(fr.u), int(fr.v)),
          cur.pyramid.level(fc.level), Eigen::Vector2f(fc.u, fc.v), options.window_size,
          static_cast<float>(options.max_subpixel_shift_px));
      if (!r.ok) continue;
      m.cur_point = sensors::point_at_frame_time(lens, cur.motion, to_level0(r.position.x(), fc.level),
                                        to_level0(r.position.y(), fc.level), fc.depth_m, &m.cur_ideal);
    }
    matches.push_back(m);
  }
}

}  // namespace kestrel::vo
