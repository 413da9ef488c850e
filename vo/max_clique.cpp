#include "vo/max_clique.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace kestrel::vo {

void BitGraph::reset(int vertices) {
  n_ = vertices;
  words_ = (vertices + 63) / 64;
  bits_.assign(static_cast<size_t>(n_) * static_cast<size_t>(words_), 0);
}

void BitGraph::connect(int a, int b) {
  if (a == b) return;
  row(a)[static_cast<size_t>(b) >> 6] |= uint64_t{1} << (b & 63);
  row(b)[static_cast<size_t>(a) >> 6] |= uint64_t{1} << (a & 63);
}

int BitGraph::degree(int a) const {
  int d = 0;
  const uint64_t* r = row(a);
  for (int w = 0; w < words_; ++w) d += __builtin_popcountll(r[w]);
  return d;
}

std::vector<int> greedy_max_clique(const BitGraph& graph) {
  const int n = graph.size();
  std::vector<int> clique;
  if (n == 0) return clique;
  std::vector<int> degree(static_cast<size_t>(n));
  for (int v = 0; v < n; ++v) degree[static_cast<size_t>(v)] = graph.degree(v);
  std::vector<int> order(static_cast<size_t>(n));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int a, int b) {
    return degree[static_cast<size_t>(a)] > degree[static_cast<size_t>(b)];
  });
  // Candidates only shrink, so taking the highest-degree candidate each time is a single pass
  // over the vertices in order of degree, keeping those still adjacent to the whole clique.
  std::vector<uint64_t> candidates(static_cast<size_t>(graph.words()), ~uint64_t{0});
  for (int v : order) {
    if (!((candidates[static_cast<size_t>(v) >> 6] >> (v & 63)) & 1u)) continue;
    clique.push_back(v);
    const uint64_t* r = graph.row(v);
    for (int w = 0; w < graph.words(); ++w) candidates[static_cast<size_t>(w)] &= r[w];
  }
  std::sort(clique.begin(), clique.end());
  return clique;
}

void build_consistency_graph(const std::vector<Eigen::Vector3f>& ref_points,
                             const std::vector<Eigen::Vector3f>& cur_points,
                             const std::vector<float>& variances, float min_tolerance,
                             float sigmas, BitGraph& graph) {
  const int n = static_cast<int>(ref_points.size());
  graph.reset(n);
  // Structure of arrays and a branch-free inner loop that the compiler vectorises; the flags of
  // one row are packed into bits afterwards.
  std::vector<float> px(ref_points.size()), py(px.size()), pz(px.size());
  std::vector<float> qx(px.size()), qy(px.size()), qz(px.size()), var(px.size());
  for (size_t i = 0; i < px.size(); ++i) {
    px[i] = ref_points[i].x(); py[i] = ref_points[i].y(); pz[i] = ref_points[i].z();
    qx[i] = cur_points[i].x(); qy[i] = cur_points[i].y(); qz[i] = cur_points[i].z();
    var[i] = variances[i];
  }
  const float min_tol2 = min_tolerance * min_tolerance;
  const float s2 = sigmas * sigmas;
  std::vector<uint8_t> flag(px.size());
  for (int a = 0; a < n; ++a) {
    const size_t sa = static_cast<size_t>(a);
    const float ax = px[sa], ay = py[sa], az = pz[sa], bx = qx[sa], by = qy[sa], bz = qz[sa];
    const float va = var[sa];
    for (size_t b = sa + 1; b < px.size(); ++b) {
      const float dpx = px[b] - ax, dpy = py[b] - ay, dpz = pz[b] - az;
      const float dqx = qx[b] - bx, dqy = qy[b] - by, dqz = qz[b] - bz;
      const float dp = std::sqrt(dpx * dpx + dpy * dpy + dpz * dpz);
      const float dq = std::sqrt(dqx * dqx + dqy * dqy + dqz * dqz);
      const float e = dp - dq;
      const float tol2 = std::max(min_tol2, s2 * (va + var[b]));
      flag[b] = e * e < tol2;
    }
    uint64_t* row = graph.row(a);
    for (size_t b = sa + 1; b < px.size(); ++b) {
      if (!flag[b]) continue;
      row[b >> 6] |= uint64_t{1} << (b & 63);
      graph.row(static_cast<int>(b))[sa >> 6] |= uint64_t{1} << (sa & 63);
    }
  }
}

}  // namespace kestrel::vo
