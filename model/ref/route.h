// Which units a ray goes to (`--route`, architecture file "route"). The paper broadcasts every
// ray to every unit; a unit that holds nothing near the ray then still tests it against all
// its spheres (or its tree's root), which caps what any structure inside a unit can save.
//  - broadcast: every unit, one wave (the paper's).
//  - multicast: the units whose bound the ray enters before its end (tmax: infinity for a
//    primary ray, the light for a shadow ray), one wave.
//  - ordered: those units in order of the distance at which the ray enters their bounds, in
//    waves of `wave` units: a unit is skipped when the ray enters its bound beyond the
//    closest hit the waves before found (hit_box with that limit says no), and a shadow ray
//    stops after the wave that found an occluder.
// A unit's bound is the box of its spheres' world bounds for the frame (ref/top_tree.h:
// world_bounds, which holds every point a kernel may report in a sphere), refitted by the
// GPP every frame from the new matrices as the units' trees are, and rounded outward to T;
// or, with per-sphere bounds, those boxes themselves (a ray enters the unit where it first
// enters one of them): more tests per ray, but two distant spheres of one unit no longer
// make it receive every ray that crosses the space between them.
// The image is the broadcast's, bit for bit: a unit whose bound the ray does not enter can
// report no hit on it; a unit entered strictly beyond the closest hit so far can report only
// a farther one (the argument of the tree over a unit's spheres, ref/top_traverse.h); and the
// nearest of the answers is chosen by the total order (t, object, prim), whichever units and
// in whichever order they came.
#pragma once

#include "geom/bvh.h"
#include "ref/top_tree.h"
#include "ref/traverse.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace oprt {

enum class Route { broadcast, multicast, ordered };

template <typename T>
struct RouteTable {
  Route route = Route::broadcast;
  std::uint32_t wave = 1;       // ordered: units per wave
  bool per_sphere = false;      // a box per visible sphere rather than one per unit
  std::vector<Box<T>> bound;    // per unit: world space, rounded outward; empty: nothing visible
  std::vector<std::uint32_t> first;  // per_sphere: unit u's boxes are boxes[first[u] .. first[u + 1])
  std::vector<Box<T>> boxes;
  // Replicated spheres (--replicate, a sphere in several units' lists): each visible one has
  // its own box, outside its units' bounds, and a ray that enters it goes to one copy, the
  // one whose share it is (share_copy of the ray's key): copy i is the i-th unit, in unit
  // order, holding it. So the router tests one box more per replicated sphere, and a copy
  // receives only its share of the rays that sphere would receive.
  std::vector<Box<T>> shared_box;
  std::vector<std::uint32_t> shared_first;  // replicated sphere i's units: shared_units[shared_first[i] ..)
  std::vector<std::uint32_t> shared_units;

  // Boxes the router tests a ray against.
  std::size_t tested() const { return (per_sphere ? boxes.size() : bound.size()) + shared_box.size(); }

  bool routed() const { return route != Route::broadcast; }
  // The frame's bounds: per unit the union of its visible spheres' world bounds (those held
  // by one unit only), and one box per visible replicated sphere.
  void refit(const FrameSetup<T>& f, const SceneGeometry<T>& g, const std::vector<std::vector<std::uint32_t>>& units) {
    bound.assign(units.size(), Box<T>{});
    first.assign(per_sphere ? units.size() + 1 : 0, 0);
    boxes.clear();
    shared_box.clear();
    shared_first.assign(1, 0);
    shared_units.clear();
    std::vector<std::uint32_t> holders(g.sphere_count(), 0);
    for (const auto& spheres : units)
      for (std::uint32_t s : spheres) ++holders[s];
    for (std::size_t u = 0; u < units.size(); ++u) {
      Box<double> b;
      for (std::uint32_t s : units[u])
        if (f.visible[s] && holders[s] == 1) {
          const Box<double> w = world_bounds(f, g, s);
          b.extend(w);
          if (per_sphere && !w.empty()) boxes.push_back(round_out<T>(w, 0));
        }
      if (!b.empty()) bound[u] = round_out<T>(b, 0);
      if (per_sphere) first[u + 1] = static_cast<std::uint32_t>(boxes.size());
    }
    for (std::uint32_t s = 0; s < holders.size(); ++s) {
      if (holders[s] < 2 || !f.visible[s]) continue;
      const Box<double> w = world_bounds(f, g, s);
      if (w.empty()) continue;
      shared_box.push_back(round_out<T>(w, 0));
      for (std::uint32_t u = 0; u < units.size(); ++u)
        if (std::find(units[u].begin(), units[u].end(), s) != units[u].end()) shared_units.push_back(u);
      shared_first.push_back(static_cast<std::uint32_t>(shared_units.size()));
    }
  }
  // The unit holding replicated sphere i's copy whose share a ray of key `key` is.
  std::uint32_t shared_owner(std::size_t i, std::uint32_t key) const {
    const std::uint32_t n = shared_first[i + 1] - shared_first[i];
    return shared_units[shared_first[i] + share_copy(key, n)];
  }
  // The units whose bound the ray enters, with their entry distances: in unit order
  // (multicast), or nearest first, ties by unit (ordered). Returns their count. `key`: the
  // ray's share key (ref/traverse.h: share_key).
  struct Entered {
    T entry;
    std::uint32_t unit;
  };
  std::size_t entered(const Ray<T>& ray, std::vector<Entered>& out, std::uint32_t key = 0) const {
    out.clear();
    const BoxRay<T> br = box_ray(ray);
    for (std::uint32_t u = 0; u < bound.size(); ++u) {
      T t = kInf<T>;
      if (!per_sphere) t = box_entry(br, bound[u], ray.tmax);
      else
        for (std::uint32_t i = first[u]; i < first[u + 1]; ++i) t = std::min(t, box_entry(br, boxes[i], ray.tmax));
      if (t != kInf<T>) out.push_back({t, u});
    }
    bool added = false;
    for (std::size_t i = 0; i < shared_box.size(); ++i) {
      const T t = box_entry(br, shared_box[i], ray.tmax);
      if (t == kInf<T>) continue;
      const std::uint32_t u = shared_owner(i, key);
      auto it = std::find_if(out.begin(), out.end(), [u](const Entered& e) { return e.unit == u; });
      if (it != out.end()) it->entry = std::min(it->entry, t);
      else {
        out.push_back({t, u});
        added = true;
      }
    }
    if (route == Route::ordered)
      std::sort(out.begin(), out.end(),
                [](const Entered& a, const Entered& b) { return a.entry != b.entry ? a.entry < b.entry : a.unit < b.unit; });
    else if (added)
      std::sort(out.begin(), out.end(), [](const Entered& a, const Entered& b) { return a.unit < b.unit; });
    return out.size();
  }
  // Whether the ray still has to visit unit u, with the closest hit so far at `limit`.
  bool worth(const Ray<T>& ray, std::uint32_t u, T limit, std::uint32_t key = 0) const {
    const BoxRay<T> br = box_ray(ray);
    if (!per_sphere) {
      if (hit_box(br, bound[u], limit)) return true;
    } else {
      for (std::uint32_t i = first[u]; i < first[u + 1]; ++i)
        if (hit_box(br, boxes[i], limit)) return true;
    }
    for (std::size_t i = 0; i < shared_box.size(); ++i)
      if (shared_owner(i, key) == u && hit_box(br, shared_box[i], limit)) return true;
    return false;
  }
};

}  // namespace oprt
