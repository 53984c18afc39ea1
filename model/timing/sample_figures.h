// A sampled frame's figures pixel by pixel (--sample: sample/pixel_sample.h), from its trace
// and the recipe's rules, for the estimates of the whole frame and their intervals
// (testbench/sample_estimate.h). Every figure here is a sum over the frame's rays, so each
// traced pixel's share is exact: the work each unit did on the pixel's rays (a ray sent to a
// unit that entered none of its spheres: the tests of its registers), the bytes each unit
// read from object memory, and the pixel's rays, the GPP's cycles for them (generation,
// routing, shading), their bus traffic and the cycles it holds a shared bus. The same at
// every level (the trace's). Plain C++.
#pragma once

#include "arch/arch.h"
#include "ref/functional_frame.h"
#include "timing/ray_figures.h"

#include <cstdint>
#include <vector>

namespace oprt::timing {

struct SampleFrame {
  enum Extra { rays, gpp_cycles, bus_cycles, bus_bytes, unit_writes, kExtras };
  std::size_t units = 0;
  std::vector<double> y;               // [pixel * figures() + figure]
  std::vector<std::uint64_t> records;  // per unit: its sampled (ray, unit) pairs that entered a sphere
  std::size_t figures() const { return 2 * units + kExtras; }
  // The figures' places: unit u's work cycles, its bytes read, and the others.
  std::size_t work(std::size_t u) const { return u; }
  std::size_t bytes(std::size_t u) const { return units + u; }
  std::size_t extra(Extra e) const { return 2 * units + static_cast<std::size_t>(e); }
  std::size_t pixels() const { return figures() ? y.size() / figures() : 0; }
};

// Frame f's figures per traced pixel on `units` units; `route_cycles(entered)` is the router's
// cycles for a ray whose route entered that many units' bounds (GppPlan::route_cycles).
template <typename T, typename RouteCycles>
SampleFrame sample_figures(const FunctionalFrame<T>& f, const Arch& a, std::size_t units, RouteCycles&& route_cycles) {
  SampleFrame s;
  s.units = units;
  const std::size_t pixels = f.pixel_rays.size() - 1, k = s.figures();
  s.y.assign(pixels * k, 0.0);
  std::vector<double> miss(units);
  for (std::uint32_t u = 0; u < units; ++u) miss[u] = static_cast<double>(f.cycles(nullptr, u));
  for (std::uint32_t id = 0; id < f.ray_count(); ++id) {
    const RayRecord<T>& r = f.rays[id];
    double* y = &s.y[r.pixel * k];
    const RayTraffic t = ray_traffic(f, a, units, id);
    y[s.extra(SampleFrame::rays)] += 1;
    y[s.extra(SampleFrame::gpp_cycles)] += static_cast<double>(a.gpp.cycles_per_ray) +
                                            (r.hit() ? static_cast<double>(a.gpp.cycles_per_hit) : 0.0) +
                                            static_cast<double>(route_cycles(f.routed ? f.route_entered(id) : 0));
    y[s.extra(SampleFrame::bus_cycles)] += static_cast<double>(t.bus_cycles);
    y[s.extra(SampleFrame::bus_bytes)] += static_cast<double>(t.ray_bytes + t.answer_bytes);
    y[s.extra(SampleFrame::unit_writes)] += static_cast<double>(t.writes);
    if (!f.routed) {
      for (std::uint32_t u = 0; u < units; ++u) y[u] += miss[u];
      continue;
    }
    const auto [first, last] = f.route_of(id);
    for (const std::uint32_t* p = first; p != last; ++p) y[*p & ~kWaveEnd] += miss[*p & ~kWaveEnd];
  }
  s.records.assign(units, 0);
  for (std::uint32_t u = 0; u < units; ++u) {
    s.records[u] = f.units[u].work.size();
    for (const UnitRayWork& w : f.units[u].work) {
      double* y = &s.y[f.rays[w.ray].pixel * k];
      y[s.work(u)] += static_cast<double>(w.cycles) - miss[u];
      y[s.bytes(u)] += static_cast<double>(w.bytes);
    }
  }
  return s;
}

}  // namespace oprt::timing
