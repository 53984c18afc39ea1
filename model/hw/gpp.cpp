#include "hw/gpp.h"

#include "ref/stop.h"
#include "timing/gpp_recipe.h"

#include <algorithm>

namespace oprt::hw {

using timing::issue_ray, timing::retire_ray, timing::start_frame;

using namespace sc_core;

template <typename T>
Gpp<T>::Gpp(const sc_module_name& name, const Scene& scene, const SceneGeometry<T>& geometry, const Arch& arch,
            FunctionalFrame<T>& frame, VcdWriter* vcd, TimelineWriter* timeline)
    : sc_module(name),
      host("host"),
      hits("hits"),
      bus("bus"),
      fifos("fifos"),
      scene_(scene),
      geom_(geometry),
      arch_(arch),
      frame_(frame),
      cycle_(arch.cycle_ns(), SC_NS),
      plan_(scene, geometry, arch),
      clock_(arch.level == Level::lt ? LocalClock::Mode::quantum : LocalClock::Mode::exact),
      sync_on_bus_(arch.bus.model == BusModel::shared && arch.bus.lt_arbitration == LtArbitration::sync),
      vcd_(vcd),
      timeline_(timeline) {
  host.register_b_transport(this, &Gpp::host_transport);
  hits.register_b_transport(this, &Gpp::hit_transport);
  if (vcd_) {
    vcd_in_flight_ = vcd_->add(this->name(), "rays_in_flight", 32);
    vcd_frame_ = vcd_->add(this->name(), "frame", 32);
    vcd_kind_ = vcd_->add(this->name(), "ray_kind", 2);  // of the ray last issued: RayKind's code
    if (arch.top_tree() || arch.routed()) vcd_refit_ = vcd_->add(this->name(), "refit", 1);
    if (arch.routed()) {
      vcd_routing_ = vcd_->add(this->name(), "routing", 1);
      vcd_fanout_ = vcd_->add(this->name(), "fanout", 16);
    }
  }
  if (timeline_ && (track_ = timeline_->track(this->name(), "gpp", "GPP")) == TimelineWriter::kNotTraced)
    timeline_ = nullptr;
  if (timeline_ && arch.routed()) router_track_ = timeline_->track(std::string(this->name()) + ".router", "gpp", "Router");
  SC_THREAD(run);
}

template <typename T>
void Gpp<T>::host_transport(tlm::tlm_generic_payload& p, sc_time&) {
  const auto* e = extension_of<FrameExtension>(p);
  if (!e || !e->command) {
    p.set_response_status(tlm::TLM_GENERIC_ERROR_RESPONSE);
    return;
  }
  command_ = e->command;
  request_.notify();
  wait(done_);
  p.set_response_status(tlm::TLM_OK_RESPONSE);
}

template <typename T>
void Gpp<T>::run() {
  for (;;) {
    wait(request_);
    clock_.resync();
    in_frame_ = true;
    if (command_->setup_only)
      for (const MemoryLoad& l : plan_.memory_loads()) load(l);
    else render_frame(*command_);
    in_frame_ = false;
    clock_.sync();
    done_.notify();
  }
}

template <typename T>
void Gpp<T>::write(tlm::tlm_generic_payload& p) {
  if (sync_on_bus_) clock_.sync();  // bus.lt_arbitration = sync (bus.h)
  sc_time delay = clock_.offset();
  const sc_time sim = sc_time_stamp();
  bus->b_transport(p, delay);
  if (p.is_response_error()) {
    char address[32];
    std::snprintf(address, sizeof address, "%llx", static_cast<unsigned long long>(p.get_address()));
    SC_REPORT_FATAL(name(), ("bus write to 0x" + std::string(address) + " failed: " + p.get_response_string()).c_str());
  }
  clock_.advance_to(sim + delay);
}

// The FIFOs the next write goes to: every one, or a routed ray's wave's.
template <typename T>
template <typename F>
void Gpp<T>::for_wave_fifos(std::uint32_t id, F&& f) const {
  const auto wave = work_->wave(id);
  if (!wave.first) {
    for (int i = 0; i < fifos.size(); ++i) f(i);
    return;
  }
  for (const std::uint32_t* p = wave.first; p != wave.last; ++p) f(static_cast<int>(*p & ~kWaveEnd));
}

template <typename T>
int Gpp<T>::full_fifo() const {
  if (arch_.fifo_depth == 0) return -1;
  int full = -1;
  for_wave_fifos(work_->peek_ray(), [&](int i) {
    if (full < 0 && !fifos[i]->has_space()) full = i;
  });
  return full;
}

// Wait for an answer, or for room in the (first) full FIFO if a ray is waiting to be
// written (a unit popping another FIFO changes nothing the GPP waits for), or until the
// deadline: the time of the next work item already known (temporal decoupling only).
template <typename T>
void Gpp<T>::wait_for_space_or_answers(bool want_space, const sc_time* deadline) {
  if (clock_.offset() != SC_ZERO_TIME) {  // catch up first; the caller looks again
    clock_.sync();
    return;
  }
  const int full = want_space ? full_fifo() : -1;
  waiting_on_fifo_ = full;
  wake_before_ = deadline ? *deadline : sc_max_time();
  if (deadline && full >= 0) wait(*deadline - sc_time_stamp(), answered_ | fifos[full]->freed_event());
  else if (deadline) wait(*deadline - sc_time_stamp(), answered_);
  else if (full >= 0) wait(answered_ | fifos[full]->freed_event());
  else wait(answered_);
  wake_before_ = SC_ZERO_TIME;
  // Units finishing in the same time step answer within its first delta cycle: let them
  // all arrive, so that simultaneous completions are handled in ray order.
  wait(SC_ZERO_TIME);
  clock_.resync();
}

// When every ray FIFO has room for the next write (call only when none is full): under
// temporal decoupling the pop that made room may lie ahead of the GPP's local time.
template <typename T>
sc_time Gpp<T>::room_time(std::uint32_t id) const {
  sc_time t = clock_.now();
  if (arch_.fifo_depth == 0) return t;
  for_wave_fifos(id, [&](int i) { t = std::max(t, fifos[i]->space_time()); });
  return t;
}

template <typename T>
void Gpp<T>::trace_in_flight() {
  if (vcd_) vcd_->change(vcd_in_flight_, clock_.now().value(), issued_ - retired_);
}

// Write ray `id`'s next wave (gpp_recipe.h): room first, as at `at`; then the recipe.
template <typename T>
void Gpp<T>::issue(std::uint32_t id) {
  clock_.advance_to(room_time(id));
  current_ray_ = id;
  issue_ray(plan_, *work_, id, arch_, *this);
}

// The recipe's clock (gpp_recipe.h): the GPP's cycles on its local clock, shown in the
// waveform and the timeline.
template <typename T>
void Gpp<T>::compute(GppPhase phase, std::uint64_t cycles) {
  // The timeline names the GPP's work on a ray by the ray's kind.
  static constexpr const char* issue[kRayKinds] = {"issue primary", "issue shadow", "issue reflection",
                                                   "issue refraction"};
  static constexpr const char* shade[kRayKinds] = {"shade primary", "shade shadow", "shade reflection",
                                                   "shade refraction"};
  const sc_time start = clock_.now();
  const int signal = phase == GppPhase::refit ? vcd_refit_ : phase == GppPhase::route ? vcd_routing_ : -1;
  if (vcd_ && signal >= 0) vcd_->change(signal, start.value(), 1);
  clock_.advance(cycle_ * static_cast<double>(cycles));
  if (vcd_ && signal >= 0) vcd_->change(signal, clock_.now().value(), 0);
  if (phase == GppPhase::route) stats_.route_cycles += cycles;
  if (phase == GppPhase::refit && timeline_)
    timeline_->slice(track_, "refit", start.value(), clock_.now().value(), {{"nodes", plan_.config().refit_nodes}});
  else if (phase == GppPhase::route && router_track_ >= 0)
    timeline_->slice(router_track_, "route", start.value(), clock_.now().value(),
                     {{"ray", current_ray_}, {"units", work_->wave(current_ray_).size(units_)}});
  else if (phase != GppPhase::refit && timeline_) {
    const RayRecord<T>& r = frame_.rays[current_ray_];
    const int k = static_cast<int>(r.kind);
    timeline_->slice(track_, phase == GppPhase::shade ? shade[k] : phase == GppPhase::route ? "route" : issue[k],
                     start.value(), clock_.now().value(), {{"ray", current_ray_}, {"depth", r.depth}});
  }
}

template <typename T>
void Gpp<T>::generated(std::uint32_t id) {
  ++issued_;
  ++stats_.rays[static_cast<int>(frame_.rays[id].kind)];
  if (vcd_ && vcd_kind_ >= 0) vcd_->change(vcd_kind_, clock_.now().value(), static_cast<std::uint64_t>(frame_.rays[id].kind));
  trace_in_flight();
}

template <typename T>
void Gpp<T>::routed_nowhere(std::uint32_t id) {  // the router's answer (a miss, not occluded) is the ray's
  if (vcd_ && vcd_fanout_ >= 0) vcd_->change(vcd_fanout_, clock_.now().value(), 0);
  pending_[id].answers_left = 0;
  completed_at_[id] = clock_.now();
  work_->answered(clock_.now(), id);
}

// The wave's writes: to every FIFO (broadcast), to the wave's FIFOs in one transfer with a
// unit mask after the ray's bytes, or one transfer per unit.
template <typename T>
template <typename Wave>
void Gpp<T>::write_rays(std::uint32_t id, const Wave& wave, const RayWrites& w) {
  const std::size_t n = wave.size(units_);
  pending_[id].answers_left = static_cast<std::uint32_t>(n);
  if (vcd_ && vcd_fanout_ >= 0) vcd_->change(vcd_fanout_, clock_.now().value(), n);
  const auto bytes = static_cast<unsigned>(w.ray_bytes);
  unsigned char* data = ray_bytes_.data(bytes + units_);
  WireRay<T>::write(data, id, frame_.rays[id], arch_.top_tree());
  if (w.kind == RayWrites::Kind::broadcast) {
    prepare(ray_, tlm::TLM_WRITE_COMMAND, addr::broadcast_rays, data, bytes);
    write(ray_);
  } else if (w.kind == RayWrites::Kind::masked) {
    const unsigned mask_bytes = static_cast<unsigned>(w.bytes - w.ray_bytes);  // one bit per unit; the bus delivers to those
    std::fill(data + bytes, data + bytes + mask_bytes, 0);
    for (const std::uint32_t* p = wave.first; p != wave.last; ++p) {
      const std::uint32_t u = *p & ~kWaveEnd;
      data[bytes + u / 8] |= static_cast<unsigned char>(1u << (u % 8));
    }
    prepare(ray_, tlm::TLM_WRITE_COMMAND, addr::multicast_rays, data, bytes + mask_bytes);
    write(ray_);
  } else {
    for (const std::uint32_t* p = wave.first; p != wave.last; ++p) {
      prepare(ray_, tlm::TLM_WRITE_COMMAND, addr::iu_window(static_cast<int>(*p & ~kWaveEnd)) + addr::iu_ray_fifo, data,
              bytes);
      write(ray_);
    }
  }
}

template <typename T>
void Gpp<T>::hit_transport(tlm::tlm_generic_payload& p, sc_time& delay) {
  WireAnswer<T> a;
  if (p.get_command() != tlm::TLM_WRITE_COMMAND || !a.read(p.get_data_ptr(), p.get_data_length()) ||
      a.ray >= pending_.size() || !pending_[a.ray].answers_left) {
    p.set_response_status(tlm::TLM_GENERIC_ERROR_RESPONSE);
    return;
  }
  Pending& r = pending_[a.ray];
  r.occluded = r.occluded || a.occluded;
  if (a.hit.valid() && closer(a.hit, r.hit)) r.hit = a.hit;
  completed_at_[a.ray] = std::max(completed_at_[a.ray], sc_time_stamp() + delay);
  if (--r.answers_left == 0) {
    work_->answered(completed_at_[a.ray], a.ray);
    // Wake the GPP only if it waits for something later than this completion (a unit
    // running ahead answers long before the answer is due; the GPP's deadline covers it).
    if (completed_at_[a.ray] < wake_before_) answered_.notify();
  }
  p.set_response_status(tlm::TLM_OK_RESPONSE);
}

// A pixel's colour is the traced one; the GPP checked every answer that went into it.
template <typename T>
void Gpp<T>::finish_pixel(std::uint32_t pixel, FrameImage& img) const {
  img.r[pixel] = frame_.image.r[pixel];
  img.g[pixel] = frame_.image.g[pixel];
  img.b[pixel] = frame_.image.b[pixel];
}

template <typename T>
void Gpp<T>::retire(std::uint32_t id, const FrameCommand& cmd) {
  clock_.advance_to(completed_at_[id]);
  const RayRecord<T>& rec = frame_.rays[id];
  const Pending& pr = pending_[id];
  FrameImage& img = *cmd.image;
  const std::uint32_t p = rec.pixel;        // its place among the pixels traced
  const std::uint32_t q = frame_.frame_pixel(p);  // and in the image
  ++retired_;
  if (rec.kind == RayKind::primary) {
    if (progress_ && (++primaries_retired_ & 4095) == 0) progress_(primaries_retired_, pixel_count_);
    rays_left_[p] = frame_.pixel_rays[p + 1] - frame_.pixel_rays[p];
    if (pr.hit.valid()) {
      img.z[q] = static_cast<float>(pr.hit.t);
      img.object[q] = pr.hit.object;
      img.prim[q] = pr.hit.prim;
    }
  }
  // The merged answers must be the traced nearest hit: the units' answers are the
  // functional work's, so anything else is a fault in the model's plumbing. (A hit is shaded,
  // gpp.cycles_per_hit, by the recipe's retire_ray, and the rays it spawns are queued.)
  if (seeks_nearest(rec.kind) &&
      (pr.hit.valid() != rec.hit() ||
       (pr.hit.valid() && (pr.hit.object != rec.object || pr.hit.prim != rec.prim || static_cast<float>(pr.hit.t) != rec.t))))
    SC_REPORT_FATAL(name(), ("ray " + std::to_string(id) + ": the units' answers disagree with the functional trace").c_str());
  if (--rays_left_[p] == 0) finish_pixel(q, img);  // every ray of the pixel's tree is in
  trace_in_flight();
}

// The plan's loads (gpp_plan.h): the set-up command loads every memory, outside any frame;
// a frame writes what moved or deforms, over the bus, before its rays (start_frame).
template <typename T>
void Gpp<T>::load(const MemoryLoad& l) {
  stats_.memory_load_bytes += l.bytes;
  stats_.unit_memory_load_bytes.resize(plan_.units(), 0);
  stats_.unit_memory_load_bytes[l.unit] += l.bytes;
  const sc_time before = clock_.now();
  LoadExtension& e = prepare<LoadExtension>(load_, tlm::TLM_WRITE_COMMAND,
                                            addr::iu_window(static_cast<int>(l.unit)) + addr::iu_memory,
                                            bulk_bytes_.data(l.bytes), static_cast<unsigned>(l.bytes));
  e.load = &l;
  write(load_);
  stats_.memory_load_cycles += static_cast<std::uint64_t>((clock_.now() - before) / cycle_ + 0.5);
}

template <typename T>
void Gpp<T>::write_config(std::uint32_t u, std::uint64_t bytes64) {
  const auto bytes = static_cast<unsigned>(bytes64);
  stats_.config_bytes += bytes;
  ConfigExtension<T>& e = prepare<ConfigExtension<T>>(config_, tlm::TLM_WRITE_COMMAND,
                                                      addr::iu_window(static_cast<int>(u)) + addr::iu_config,
                                                      bulk_bytes_.data(bytes), bytes);
  e.registers = &plan_.registers()[u];
  e.cached = plan_.cached(u);
  write(config_);
}

template <typename T>
void Gpp<T>::render_frame(const FrameCommand& cmd) {
  stats_ = GppStats{};
  stats_.start = clock_.now();
  if (vcd_) vcd_->change(vcd_frame_, stats_.start.value(), static_cast<std::uint64_t>(cmd.frame));
  // Geometry that moved or deforms (the set-up command loaded the rest), the refit of the
  // units' trees, the configuration registers (gpp_recipe.h).
  units_ = static_cast<unsigned>(plan_.units());
  const auto& config = start_frame(plan_, cmd, *this);
  stats_.started = clock_.now();
  stats_.refit_nodes = config.refit_nodes;
  stats_.refit_cycles = config.refit_cycles;
  stats_.built_nodes = config.built_nodes;

  // The frame's functional work, on every thread the pool allows (functional_frame.h).
  try {
    plan_.trace(frame_, cmd, vcd_ != nullptr || timeline_ != nullptr);
  } catch (const Interrupted&) {  // SIGINT / SIGTERM: abandon the frame; the testbench says what completed
    sc_stop();
    wait(abandoned_);  // never notified
  }

  const std::size_t pixels = frame_.pixel_rays.size() - 1;  // traced (with --sample, the sample's)
  pending_.assign(frame_.ray_count(), Pending{});
  completed_at_.assign(frame_.ray_count(), SC_ZERO_TIME);
  rays_left_.assign(pixels, 0);
  work_ = std::make_unique<GppWork<T, sc_time>>(frame_);
  issued_ = retired_ = 0;
  primaries_retired_ = 0;
  pixel_count_ = pixels;
  // The GPP's next work item (GppWork): the earlier of (a) handling an answered ray, due
  // when its last answer arrived, and (b) writing the next ray (a shadow ray first),
  // possible once every FIFO has room; on a tie (a). At `at` both are always due by the
  // time the GPP looks. Under temporal decoupling either can lie in the GPP's future: a
  // unit running ahead answers, or pops, early in simulation order. The GPP then does not
  // jump its clock to that time (it would handle that answer before answers due earlier
  // that lagging units have yet to send, and hold back every ray it would have written
  // meanwhile) but waits in simulation time until it is due, or until something earlier
  // turns up.
  const sc_time never = sc_max_time();
  for (;;) {
    if (stop_signal()) {  // SIGINT / SIGTERM: abandon the frame; the testbench says what completed
      sc_stop();
      wait(abandoned_);  // never notified
    }
    const bool has_ray = work_->has_ray();
    const bool room = has_ray && full_fifo() < 0;
    const sc_time ready = room ? room_time(work_->peek_ray()) : never;
    const auto next = work_->next(clock_.now(), ready, never, retired_ == issued_);
    if (next == GppWork<T, sc_time>::Next::done) break;
    if (next == GppWork<T, sc_time>::Next::retire) {
      current_ray_ = work_->due_ray();
      const auto r = retire_ray(*work_, arch_, *this);
      if (r.next_wave) clock_.advance_to(completed_at_[r.ray]);  // the wave is in; the next one is queued
      else retire(r.ray, cmd);
    } else if (next == GppWork<T, sc_time>::Next::issue) {
      issue(work_->take_ray(clock_.now()));
    } else {
      const sc_time due = std::min(work_->due(never), ready);
      wait_for_space_or_answers(has_ray && !room, due == never ? nullptr : &due);
    }
  }
  stats_.end = clock_.now();
  stats_.waiting = work_->waiting();
  if (timeline_)
    timeline_->slice(track_, "frame", stats_.start.value(), stats_.end.value(),
                     {{"frame", static_cast<std::uint64_t>(cmd.frame)}, {"rays", issued_}});
}

template <typename T>
std::string Gpp<T>::waiting_for() const {
  if (!in_frame_) return "idle, waiting for a frame command";
  if (command_->setup_only) return "loading object memories";
  std::string s = "frame " + std::to_string(command_->frame) + ": " + std::to_string(issued_) + " rays issued, " +
                  std::to_string(retired_) + " retired; waiting for answers";
  if (waiting_on_fifo_ >= 0) {
    const auto* f = dynamic_cast<const sc_object*>(fifos[waiting_on_fifo_]);
    s += " or for room in " + std::string(f ? f->name() : "a FIFO") + " (" + fifos[waiting_on_fifo_]->fill_state() + ")";
  }
  for (std::size_t id = 0; id < pending_.size(); ++id)
    if (pending_[id].answers_left) {
      s += "; oldest ray in flight " + std::to_string(id) + " has " + std::to_string(units_ - pending_[id].answers_left) +
           " of " + std::to_string(units_) + " answers";
      break;
    }
  return s;
}

template class Gpp<float>;
template class Gpp<double>;

}  // namespace oprt::hw
