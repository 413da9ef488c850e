#include "mapper/ray.h"

namespace kestrel::mapper {

Ray make_ray(const KeySpace& keys, const octomap::point3d& origin, const Key& key_origin,
             const octomap::point3d& p, double max_range_m) {
  Ray ray;
  const octomap::point3d offset = p - origin;
  // OctoMap: norm() is the float sum of squares, square-rooted in double.
  ray.hit = offset.norm() <= max_range_m;
  if (ray.hit) {
    ray.end = p;
  } else {
    ray.end = origin + offset.normalized() * static_cast<float>(max_range_m);
  }
  bool end_in_tree = keys.key(ray.end, ray.key_end);
  if (ray.hit && !end_in_tree) ray.hit = false;  // outside the tree: no occupied cell either
  if (!end_in_tree || ray.key_end == key_origin) return ray;

  octomap::point3d dir = ray.end - origin;
  ray.length = static_cast<float>(dir.norm());
  dir /= ray.length;
  ray.dir = dir;
  for (int a = 0; a < 3; ++a) {
    ray.step[a] = dir(a) > 0.0f ? 1 : (dir(a) < 0.0f ? -1 : 0);
  }
  ray.clears = true;
  return ray;
}

}  // namespace kestrel::mapper
