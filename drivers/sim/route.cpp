#include "drivers/sim/route.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <queue>
#include <stdexcept>

#include "common/numbers.h"

namespace kestrel::sim {
namespace {

struct Grid {
  int cols = 0, rows = 0;
  double x0 = 0, y0 = 0, cell = 1, z = 0;
  std::vector<uint8_t> free;
  int index(int c, int r) const { return r * cols + c; }
  Eigen::Vector3d centre(int i) const { return {x0 + (i % cols + 0.5) * cell, y0 + (i / cols + 0.5) * cell, z}; }
};

Grid free_grid(const World& world, const RouteOptions& o) {
  Grid g;
  const Eigen::AlignedBox3d& b = world.bounds();
  g.cell = o.cell_m;
  g.x0 = b.min().x();
  g.y0 = b.min().y();
  g.z = b.min().z() + o.height_m;
  g.cols = std::max(1, static_cast<int>(b.sizes().x() / g.cell));
  g.rows = std::max(1, static_cast<int>(b.sizes().y() / g.cell));
  g.free.assign(static_cast<size_t>(g.cols) * g.rows, 0);
  for (int i = 0; i < g.cols * g.rows; ++i) g.free[i] = world.is_free(g.centre(i), o.clearance_m) ? 1 : 0;
  return g;
}

// Geodesic distances from `source` over free cells (8-connected Dijkstra) and parents.
void dijkstra(const Grid& g, int source, std::vector<double>& dist, std::vector<int>& parent) {
  dist.assign(g.free.size(), kInf);
  parent.assign(g.free.size(), -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<>> queue;
  dist[source] = 0;
  queue.push({0.0, source});
  while (!queue.empty()) {
    const auto [d, i] = queue.top();
    queue.pop();
    if (d > dist[i]) continue;
    const int c = i % g.cols, r = i / g.cols;
    for (int dr = -1; dr <= 1; ++dr)
      for (int dc = -1; dc <= 1; ++dc) {
        const int cc = c + dc, rr = r + dr;
        if ((dc == 0 && dr == 0) || cc < 0 || rr < 0 || cc >= g.cols || rr >= g.rows) continue;
        const int j = g.index(cc, rr);
        if (!g.free[j]) continue;
        // A diagonal step needs both side cells free, so paths never cut a corner.
        if (dc != 0 && dr != 0 && !(g.free[g.index(c + dc, r)] && g.free[g.index(c, r + dr)])) continue;
        const double nd = d + ((dc != 0 && dr != 0) ? std::sqrt(2.0) : 1.0) * g.cell;
        if (nd < dist[j]) {
          dist[j] = nd;
          parent[j] = i;
          queue.push({nd, j});
        }
      }
  }
}

// Grid cells from `from` to `to` (inclusive) along the parents of a search rooted at `from`.
std::vector<int> path_to(const std::vector<int>& parent, int to) {
  std::vector<int> cells;
  for (int i = to; i >= 0; i = parent[i]) cells.push_back(i);
  std::reverse(cells.begin(), cells.end());
  return cells;
}

// Closed polyline resampled at equal arc-length steps of about `spacing`.
std::vector<Eigen::Vector3d> resample_closed(const std::vector<Eigen::Vector3d>& in, double spacing) {
  std::vector<double> arc{0.0};
  for (size_t i = 0; i < in.size(); ++i) arc.push_back(arc.back() + (in[(i + 1) % in.size()] - in[i]).norm());
  const double total = arc.back();
  const int n = std::max(8, static_cast<int>(std::round(total / spacing)));
  std::vector<Eigen::Vector3d> out;
  size_t seg = 0;
  for (int k = 0; k < n; ++k) {
    const double s = total * k / n;
    while (seg + 1 < arc.size() - 1 && arc[seg + 1] <= s) ++seg;
    const double len = arc[seg + 1] - arc[seg];
    const double u = len > 0 ? (s - arc[seg]) / len : 0.0;
    out.push_back(in[seg] + u * (in[(seg + 1) % in.size()] - in[seg]));
  }
  return out;
}

}  // namespace

std::vector<Eigen::Vector3d> plan_tour(const World& world, const Eigen::Vector2d& start, const RouteOptions& o) {
  const Grid g = free_grid(world, o);
  // The free cell nearest the requested start.
  int source = -1;
  double best = kInf;
  for (int i = 0; i < static_cast<int>(g.free.size()); ++i) {
    if (!g.free[i]) continue;
    const double d = (g.centre(i).head<2>() - start).norm();
    if (d < best) best = d, source = i;
  }
  if (source < 0 || best > 2.0)
    throw std::runtime_error("world '" + world.name() + "': no free space for a route near the start");

  // Farthest-point sampling of the stops over geodesic distance.
  std::vector<int> stops{source};
  std::vector<std::vector<double>> dist(1);
  std::vector<std::vector<int>> parent(1);
  dijkstra(g, source, dist[0], parent[0]);
  for (int k = 0; k < o.stops; ++k) {
    int far = -1;
    double far_d = 0.0;
    for (int i = 0; i < static_cast<int>(g.free.size()); ++i) {
      double d = kInf;
      for (const auto& di : dist) d = std::min(d, di[i]);
      if (d < kInf && d > far_d) far_d = d, far = i;
    }
    if (far < 0 || far_d < 1.0) break;
    stops.push_back(far);
    dist.emplace_back();
    parent.emplace_back();
    dijkstra(g, far, dist.back(), parent.back());
  }
  if (stops.size() < 2) throw std::runtime_error("world '" + world.name() + "': too little free space for a route");

  // Cheapest closed order of the stops (few stops: every permutation of all but the start).
  std::vector<int> order(stops.size() - 1);
  std::iota(order.begin(), order.end(), 1);
  std::vector<int> best_order = order;
  double best_cost = kInf;
  do {
    double cost = dist[0][stops[order.front()]] + dist[order.back()][stops[0]];
    for (size_t i = 0; i + 1 < order.size(); ++i) cost += dist[order[i]][stops[order[i + 1]]];
    if (cost < best_cost) best_cost = cost, best_order = order;
  } while (std::next_permutation(order.begin(), order.end()));

  std::vector<Eigen::Vector3d> polyline;
  int at = 0;
  best_order.push_back(0);
  for (const int next : best_order) {
    const std::vector<int> cells = path_to(parent[at], stops[next]);
    for (size_t i = 0; i + 1 < cells.size(); ++i) polyline.push_back(g.centre(cells[i]));
    at = next;
  }
  return resample_closed(polyline, o.spacing_m);
}

}  // namespace kestrel::sim
