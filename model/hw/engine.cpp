#include "hw/engine.h"

#include <string>

namespace oprt::hw {

using timing::fills_leave_memory;

using namespace sc_core;

template <typename T>
Engine<T>::Engine(const sc_module_name& name, const Scene& scene, const SceneGeometry<T>& geometry, const Arch& arch,
                  std::size_t units, VcdWriter* vcd, TimelineWriter* timeline)
    : sc_module(name), host("host"), mem("mem"), geometry_(geometry), arch_(arch) {
  const bool decoupled = arch.level == Level::lt;
  gpp_ = std::make_unique<Gpp<T>>("gpp", scene, geometry, arch, frame_, vcd, timeline);
  bus_ = std::make_unique<Bus>("bus", arch, decoupled, vcd, timeline);
  const bool fills = arch.memory.sram_bytes != 0 && fills_leave_memory(arch);
  external_ = fills && arch.memory.dram.path == DramPath::external;
  if (fills && !external_) dram_ = std::make_unique<Dram>("dram", arch, units);
  const bool fill_over_bus = fills && arch.memory.dram.path == DramPath::bus;
  if (external_) {
    fills_ = std::make_unique<tlm_utils::multi_passthrough_target_socket<Engine>>("fills");
    fills_->register_b_transport(this, &Engine::fill_transport);
  }
  host.bind(gpp_->host);
  gpp_->bus.bind(bus_->in);
  bus_->out.bind(gpp_->hits);
  bus_->map(addr::gpp_hits, addr::region_size, {0}, "answer");
  std::vector<int> every_fifo;
  for (std::size_t i = 0; i < units; ++i) {
    const std::string n = std::to_string(i);
    fifos_.push_back(std::make_unique<RayFifo>(("fifo" + n).c_str(), arch.fifo_depth, vcd));
    memories_.push_back(
        std::make_unique<ObjectMemory>(("memory" + n).c_str(), static_cast<int>(i), arch, geometry.sphere_count(), vcd));
    if (arch.iu.model == IuModel::pipelined)
      units_.push_back(std::make_unique<PipelinedUnit<T>>(("iu" + n).c_str(), static_cast<int>(i), arch, geometry,
                                                          frame_, vcd, timeline));
    else
      units_.push_back(std::make_unique<SerialUnit<T>>(("iu" + n).c_str(), static_cast<int>(i), arch, geometry, frame_,
                                                       vcd, timeline));
    IntersectionUnit<T>& u = *units_.back();
    u.bus.bind(bus_->in);
    u.mem.bind(memories_.back()->read);
    if (fill_over_bus) memories_.back()->fill.bind(bus_->in);
    else if (external_) memories_.back()->fill.bind(*fills_);
    else if (fills) memories_.back()->fill.bind(dram_->in);
    u.fifo.bind(*fifos_.back());
    gpp_->fifos.bind(*fifos_.back());
    bus_->out.bind(u.cfg);
    bus_->out.bind(memories_.back()->load);
    bus_->out.bind(fifos_.back()->in);
    const int base = 1 + 3 * static_cast<int>(i);
    const std::uint64_t w = addr::iu_window(static_cast<int>(i));
    bus_->map(w + addr::iu_config, addr::iu_memory - addr::iu_config, {base}, "config");
    bus_->map(w + addr::iu_memory, addr::iu_ray_fifo - addr::iu_memory, {base + 1}, "memory load");
    bus_->map(w + addr::iu_ray_fifo, addr::iu_stride - addr::iu_ray_fifo, {base + 2}, "ray");
    every_fifo.push_back(base + 2);
  }
  bus_->map(addr::broadcast_rays, addr::region_size, every_fifo, "ray");
  if (arch.routed()) bus_->map(addr::multicast_rays, addr::region_size, every_fifo, "ray", true);
  if (fill_over_bus) {
    bus_->out.bind(dram_->in);
    bus_->map(addr::dram_base, addr::dram_size, {1 + 3 * static_cast<int>(units)}, "cache fill");
  }
}

template <typename T>
void Engine<T>::end_of_elaboration() {
  if (external_ && mem.size() == 0)
    SC_REPORT_ERROR(name(), "memory.dram.path is \"external\": bind the engine's memory port (mem) to a memory target");
}

template <typename T>
void Engine<T>::fill_transport(int, tlm::tlm_generic_payload& p, sc_time& delay) {
  mem->b_transport(p, delay);
}

template <typename T>
void Engine<T>::assign(const Assignment& a) {
  if (a.units() != units_.size())
    SC_REPORT_FATAL(name(), "assignment has a different number of units than the engine");
  assignment_ = a;
  gpp_->set_assignment(a.unit);
}

template <typename T>
void Engine<T>::reset_stats() {
  for (std::size_t u = 0; u < units(); ++u) {
    unit(u).reset_stats();
    memory(u).reset_stats();
    fifo(u).reset_counts();
  }
  bus().reset_stats();
}

template <typename T>
timing::FrameRun Engine<T>::figures() {
  const sc_time cycle(arch_.cycle_ns(), SC_NS);
  auto cycles = [&](const sc_time& t) { return static_cast<std::uint64_t>(t / cycle + 0.5); };
  const GppStats& g = gpp().stats();
  timing::FrameRun run;
  static_cast<timing::GppFigures&>(run) = g;
  run.makespan = cycles(g.end - g.start);
  run.start_cycles = cycles(g.started - g.start);
  run.bus_busy = bus().busy_cycles();
  run.bus_bytes = bus().bytes();
  run.bus_transfers = bus().transfers();
  run.route.cycles = g.route_cycles;
  timing::route_figures(frame_, units(), run.route);
  timing::ray_figures(frame_, arch_, units(), g.waiting, cycles, run.ray_figures);
  for (std::size_t u = 0; u < units(); ++u) {
    const UnitStats& s = unit(u).stats();
    const ObjectMemory& m = memory(u);
    RayFifo& f = fifo(u);
    timing::UnitTimed t;
    t.rays = timing::all_kinds(s.rays);
    t.bus_stall = s.bus_stall;
    t.cache = m.is_cache();
    t.memory = m.cache_counts();
    t.cache_stall = s.cache_stall;
    t.pipeline = s.pipeline;
    t.fifo_pushes = f.pushes();
    t.fifo_pops = f.pops();
    t.fifo_peak = f.peak_occupancy();
    if (u < g.unit_memory_load_bytes.size()) t.memory_load_bytes = g.unit_memory_load_bytes[u];
    const auto id = static_cast<std::uint32_t>(u);
    timing::UnitRun r = timing::unit_run(frame_, id, assignment_.unit[u], geometry_, arch_, t);
    // What the modules did must be the work the trace holds: anything else is a fault in
    // the model's plumbing.
    if (!s.pipeline && s.charged != r.cycles.busy() + r.memory.stall)
      SC_REPORT_FATAL(name(), ("unit " + std::to_string(u) + " waited out other cycles than its work").c_str());
    if (m.bytes_read() != r.memory_bytes)
      SC_REPORT_FATAL(name(), ("object memory " + std::to_string(u) + " was read other bytes than the work needs").c_str());
    run.units.push_back(r);
  }
  timing::report_work(frame_, run);
  if (frame_.sample)
    run.sample = timing::sample_figures(frame_, arch_, units(), [&](std::size_t entered) { return gpp().plan().route_cycles(entered); });
  return run;
}

template <typename T>
void Engine<T>::run_frame(FrameCommand& cmd) {
  const auto bytes = static_cast<unsigned>(cmd.to_world.size() * 12 * sizeof(float));  // the matrices
  prepare<FrameExtension>(command_, tlm::TLM_WRITE_COMMAND, 0, command_bytes_.data(bytes), bytes).command = &cmd;
  sc_time delay = SC_ZERO_TIME;
  host->b_transport(command_, delay);
  if (command_.is_response_error()) SC_REPORT_FATAL(name(), "frame command failed");
}

template <typename T>
void Engine<T>::setup() {
  FrameCommand cmd;
  cmd.setup_only = true;
  run_frame(cmd);
}

template class Engine<float>;
template class Engine<double>;

}  // namespace oprt::hw
