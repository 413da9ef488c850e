// The built-in experiment floor: rooms, corridor and doors as rectangles of wall.
#include "planner/floor_plan.h"

namespace kestrel::planner {

OccupancyGrid stata_like_floor() {
  OccupancyGrid g = make_grid(130, 230, 0.1, 0.05, 0.05);
  const auto wall = [&](double x0, double y0, double x1, double y1) {
    fill_rect(g, x0, y0, x1, y1, OccupancyGrid::kOccupied);
  };
  const auto door = [&](double x0, double y0, double x1, double y1) {
    fill_rect(g, x0, y0, x1, y1, OccupancyGrid::kFree);
  };
  // Outer walls (0.2 m).
  wall(0.0, 0.0, 13.0, 0.2);
  wall(0.0, 22.8, 13.0, 23.0);
  wall(0.0, 0.0, 0.2, 23.0);
  wall(12.8, 0.0, 13.0, 23.0);
  // Corridor 5.0 < x < 7.6 between two long walls.
  wall(4.9, 0.0, 5.1, 23.0);
  wall(7.5, 0.0, 7.7, 23.0);
  // West rooms (split at y = 6, 12, 17), east rooms (split at y = 8, 15).
  for (double y : {6.0, 12.0, 17.0}) wall(0.0, y - 0.1, 5.0, y + 0.1);
  for (double y : {8.0, 15.0}) wall(7.6, y - 0.1, 13.0, y + 0.1);
  // Doors into the corridor (2.4 m), and one between two west rooms.
  for (double y : {3.0, 9.0, 14.5, 20.0}) door(4.8, y - 1.2, 5.2, y + 1.2);
  for (double y : {4.0, 11.5, 19.0}) door(7.4, y - 1.2, 7.8, y + 1.2);
  door(1.4, 11.8, 3.8, 12.2);
  // A cabinet in the big east room and a pillar by the corridor's west wall.
  wall(9.5, 17.5, 11.0, 18.2);
  wall(5.1, 11.0, 5.5, 11.4);
  return g;
}

std::array<std::pair<Config, Config>, 5> stata_like_pairs() {
  return {{{Config(2.5, 2.5, 1.0, 0.0), Config(10.5, 20.0, 1.0, 0.0)},
           {Config(2.5, 20.0, 1.0, 0.0), Config(10.0, 5.0, 1.0, 0.0)},
           {Config(6.3, 1.5, 1.0, 0.0), Config(6.3, 21.5, 1.0, 0.0)},
           {Config(11.0, 12.0, 1.0, 0.0), Config(2.5, 8.0, 1.0, 0.0)},
           {Config(1.5, 14.5, 1.0, 0.0), Config(10.0, 2.0, 1.0, 0.0)}}};
}

}  // namespace kestrel::planner
