#include "analytic/engine.h"

#include "analytic/bus.h"
#include "analytic/dram.h"
#include "analytic/gpp.h"
#include "timing/gpp_recipe.h"

namespace oprt::analytic {

using timing::MemoryLoad, timing::fills_leave_memory, timing::pipeline_config, timing::ray_figures, timing::report_work,
    timing::route_figures, timing::start_frame, timing::unit_run;

template <typename T>
AnalyticEngine<T>::AnalyticEngine(const Scene& scene, const SceneGeometry<T>& geometry, const Arch& arch)
    : geom_(geometry), arch_(arch), plan_(scene, geometry, arch) {}

template <typename T>
AnalyticEngine<T>::~AnalyticEngine() = default;

template <typename T>
void AnalyticEngine<T>::assign(const Assignment& a) {
  plan_.assign(a.unit);
}

template <typename T>
void AnalyticEngine<T>::make_units(std::size_t units) {
  if (memories_.size() == units) return;
  memories_.clear();
  for (std::size_t u = 0; u < units; ++u)
    memories_.push_back(std::make_unique<ObjectMemoryModel>(arch_, static_cast<std::uint32_t>(u)));
}

template <typename T>
void AnalyticEngine<T>::setup() {
  make_units(plan_.units());
  for (const MemoryLoad& l : plan_.memory_loads()) memories_[l.unit]->load(l);
}

template <typename T>
FrameRun AnalyticEngine<T>::run_frame(const FrameCommand& cmd) {
  const std::size_t units = plan_.units();
  make_units(units);
  FrameRun out;
  out.units.resize(units);
  std::vector<UnitTimed> timed(units);
  AnalyticBus bus(arch_, units, out);
  AnalyticGpp<T> gpp(plan_, arch_, out, bus);
  gpp.on_load = [&](const MemoryLoad& l) {
    memories_[l.unit]->load(l);
    timed[l.unit].memory_load_bytes += l.bytes;
  };
  const auto& config = start_frame(plan_, cmd, gpp);
  out.start_cycles = gpp.now();
  out.refit_nodes = config.refit_nodes;
  out.refit_cycles = config.refit_cycles;
  out.built_nodes = config.built_nodes;

  // Misses contend with other units' (hw/dram.h): the shared channels, per frame.
  std::unique_ptr<AnalyticDram> dram;
  if (fills_leave_memory(arch_)) dram = std::make_unique<AnalyticDram>(arch_, units, bus);
  // This frame's time starts at 0: every fill of the last has arrived, every unit is idle.
  for (std::size_t u = 0; u < units; ++u) {
    memories_[u]->restart_time();
    memories_[u]->reset_counts();
    memories_[u]->set_fill(dram ? dram->fill(static_cast<std::uint32_t>(u)) : nullptr);
    timed[u].cache = memories_[u]->is_cache();
  }
  if (arch_.iu.model == IuModel::pipelined) pipes_.assign(units, PipelinedUnitTiming(pipeline_config(arch_)));

  plan_.trace(frame_, cmd, false);
  AnalyticFifos fifos(units, static_cast<unsigned>(arch_.fifo_depth), fifo_peak_);
  AnalyticUnits<T> iu(frame_, geom_, plan_.registers(), arch_, {memories_, pipes_, timed}, bus, fifos, gpp);
  gpp.connect(frame_, fifos, iu, dram.get());
  out.makespan = gpp.run();
  route_figures(frame_, units, out.route);
  ray_figures(frame_, arch_, units, gpp.waiting(), [](std::uint64_t c) { return c; }, out.ray_figures);
  *cmd.image = frame_.image;
  report_work(frame_, out);
  if (frame_.sample)
    out.sample = timing::sample_figures(frame_, arch_, units, [&](std::size_t entered) { return plan_.route_cycles(entered); });
  unit_figures(out, timed, fifos, iu);
  return out;
}

template <typename T>
void AnalyticEngine<T>::unit_figures(FrameRun& out, std::vector<UnitTimed>& timed, const AnalyticFifos& fifos,
                                     const AnalyticUnits<T>& units) {
  for (std::uint32_t u = 0; u < out.units.size(); ++u) {
    UnitTimed& t = timed[u];
    t.rays = t.fifo_pushes = t.fifo_pops = fifos.pushes(u);
    t.fifo_peak = fifo_peak_[u];
    t.memory = memories_[u]->counts();
    t.cache_stall = units.cache_stall(u);
    if (arch_.iu.model == IuModel::pipelined) t.pipeline = pipes_[u].stats();
    out.units[u] = unit_run(frame_, u, plan_.assignment()[u], geom_, arch_, t);
  }
}

template class AnalyticEngine<float>;
template class AnalyticEngine<double>;

}  // namespace oprt::analytic
