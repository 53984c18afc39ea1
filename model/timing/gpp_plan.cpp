#include "timing/gpp_plan.h"

#include "ref/camera.h"
#include "ref/shading.h"
#include "timing/visit_stream.h"

#include <algorithm>

namespace oprt::timing {

FpUnits router_units(const Arch& a) {
  FpUnits u = full_units(box_graph(), a.iu.add_latency, a.iu.multiply_latency);
  if (a.route.units.adders) u.adders = a.route.units.adders;
  if (a.route.units.multipliers) u.multipliers = a.route.units.multipliers;
  return u;
}

template <typename T>
GppPlan<T>::GppPlan(const Scene& scene, const SceneGeometry<T>& geometry, const Arch& arch)
    : scene_(scene), geom_(geometry), arch_(arch) {
  if (!arch.routed()) return;
  route_.route = arch.route.policy == "ordered" ? Route::ordered : Route::multicast;
  route_.wave = static_cast<std::uint32_t>(arch.route.wave);
  route_.per_sphere = arch.route.bound == "sphere";
  router_ = modulo_schedule(box_graph(), router_units(arch));
}

template <typename T>
std::uint64_t GppPlan<T>::route_cycles(std::size_t entered) const {
  if (!routed()) return 0;
  const std::uint64_t lanes = static_cast<std::uint64_t>(arch_.route.lanes);
  const std::uint64_t per_lane = (route_.tested() + lanes - 1) / lanes;
  std::uint64_t c = per_lane * static_cast<std::uint64_t>(router_.ii) + static_cast<std::uint64_t>(router_.length());
  if (route_.route == Route::ordered && entered > 1) {
    std::uint64_t log = 0;
    while ((std::uint64_t{1} << log) < entered) ++log;
    c += entered * log;
  }
  return c;
}

template <typename T>
const std::vector<MemoryLoad>& GppPlan<T>::memory_loads() {
  const std::size_t units = assignment_.size();
  loaded_.resize(units);
  cached_.resize(units, 0);
  loads_.clear();
  rewritten_.clear();
  const GeometryAddresses<T> at(geom_);
  for (std::uint32_t s = 0; s < geom_.sphere_count(); ++s)
    if (geom_.deforming[s] && arch_.memory.sram_bytes) {
      rewritten_.push_back(at.triangles_of(geom_, s));
      rewritten_.push_back(at.nodes_of(geom_, s));
    }
  for (std::size_t u = 0; u < units; ++u) {
    const bool cache = memory_is_cache(arch_, assigned_bytes(u));
    std::uint64_t bytes = 0;
    for (std::uint32_t s : assignment_[u])
      if (geom_.deforming[s] ||
          (!cache && (cached_[u] || std::find(loaded_[u].begin(), loaded_[u].end(), s) == loaded_[u].end())))
        bytes += geom_.memory_bytes(s);  // triangles, and nodes with a BVH
    if (loaded_[u] == assignment_[u] && cache == static_cast<bool>(cached_[u]) && bytes == 0) continue;
    cached_[u] = cache ? 1 : 0;
    loaded_[u] = assignment_[u];
    loads_.push_back({static_cast<std::uint32_t>(u), bytes, cache, &loaded_[u], cache ? &rewritten_ : nullptr});
  }
  return loads_;
}

template <typename T>
bool GppPlan<T>::any_cached() const {
  return std::find(cached_.begin(), cached_.end(), 1) != cached_.end();
}

template <typename T>
const typename GppPlan<T>::Config& GppPlan<T>::configure(const FrameCommand& cmd) {
  setup_ = std::make_unique<FrameSetup<T>>(setup_frame(scene_, geom_, cmd.frame, cmd.to_world, cmd.camera));
  const std::size_t units = assignment_.size();
  config_ = Config{};
  registers_.resize(units);
  trees_.resize(arch_.top_tree() ? units : 0);
  config_.bytes.assign(units, 0);
  // Replicated spheres (a sphere in several units' lists): per entry its copies and which
  // one the unit holds, the i-th unit in unit order holding it (ref/traverse.h: mine()).
  std::vector<std::uint32_t> holders(geom_.sphere_count(), 0), seen(geom_.sphere_count(), 0);
  for (const auto& spheres : assignment_)
    for (std::uint32_t s : spheres) ++holders[s];
  const bool replicated = std::any_of(holders.begin(), holders.end(), [](std::uint32_t h) { return h > 1; });
  for (std::size_t u = 0; u < units; ++u) {
    registers_[u].load(*setup_, geom_, assignment_[u]);
    if (replicated) {
      for (std::uint32_t s : assignment_[u]) {
        if (setup_->visible[s]) {
          registers_[u].copies.push_back(holders[s]);
          registers_[u].copy.push_back(seen[s]);
        }
        ++seen[s];
      }
    }
    if (arch_.top_tree())
      config_.refit_nodes += load_top(registers_[u], trees_[u], assignment_[u], *setup_, geom_, &config_.built_nodes);
    config_.bytes[u] = assignment_[u].size() * Bytes<T>::sphere_config + registers_[u].top.size() * Bytes<T>::top_node;
  }
  if (routed()) {
    // The router's unit bounds, refitted with the trees: a unit's tree's root where it has
    // one (already refitted), else one union per sphere.
    route_.refit(*setup_, geom_, assignment_);
    if (!arch_.top_tree())
      for (const auto& spheres : assignment_) config_.refit_nodes += spheres.size();
  }
  config_.refit_cycles = config_.refit_nodes * static_cast<std::uint64_t>(arch_.gpp.cycles_per_node);
  return config_;
}

template <typename T>
void GppPlan<T>::trace(FunctionalFrame<T>& out, const FrameCommand& cmd, bool traced) const {
  const CameraRays camera(cmd.camera, cmd.width, cmd.height);
  const Shader<T> shader(scene_, *setup_, arch_.gpp.depth);
  // The records' detail (which spheres, what each visit cost): for the waveform's and the
  // timeline's phases, for caches, which time each visit, and for pipelines, which
  // schedule each visit's work on their stages.
  const bool detail = traced || any_cached() || arch_.iu.model == IuModel::pipelined;
  trace_functional(out, geom_, registers_, camera, shader, arch_, cmd.width, cmd.height, detail,
                   routed() ? &route_ : nullptr, cmd.sample);
}

template class GppPlan<float>;
template class GppPlan<double>;

}  // namespace oprt::timing
