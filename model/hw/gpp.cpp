#include "hw/gpp.h"

#include "ref/camera.h"
#include "ref/stop.h"

#include <algorithm>

namespace oprt::hw {

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
      clock_(arch.level == Level::lt ? LocalClock::Mode::quantum : LocalClock::Mode::exact),
      sync_on_bus_(arch.bus.model == BusModel::shared && arch.bus.lt_arbitration == LtArbitration::sync),
      vcd_(vcd),
      timeline_(timeline) {
  host.register_b_transport(this, &Gpp::host_transport);
  hits.register_b_transport(this, &Gpp::hit_transport);
  if (vcd_) {
    vcd_in_flight_ = vcd_->add(this->name(), "rays_in_flight", 32);
    vcd_frame_ = vcd_->add(this->name(), "frame", 32);
    if (arch.top_tree()) vcd_refit_ = vcd_->add(this->name(), "refit", 1);
  }
  if (timeline_ && (track_ = timeline_->track(this->name(), "gpp", "GPP")) == TimelineWriter::kNotTraced)
    timeline_ = nullptr;
  SC_THREAD(run);
}

template <typename T>
void Gpp<T>::host_transport(tlm::tlm_generic_payload& p, sc_time&) {
  command_ = reinterpret_cast<const FrameCommand*>(p.get_data_ptr());
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
    if (command_->setup_only) load_memories();
    else render_frame(*command_);
    in_frame_ = false;
    clock_.sync();
    done_.notify();
  }
}

template <typename T>
void Gpp<T>::write(std::uint64_t address, void* data, unsigned bytes) {
  write_.set_command(tlm::TLM_WRITE_COMMAND);
  write_.set_address(address);
  write_.set_data_ptr(static_cast<unsigned char*>(data));
  write_.set_data_length(bytes);
  write_.set_response_status(tlm::TLM_INCOMPLETE_RESPONSE);
  if (sync_on_bus_) clock_.sync();  // bus.lt_arbitration = sync (bus.h)
  sc_time delay = clock_.offset();
  const sc_time sim = sc_time_stamp();
  bus->b_transport(write_, delay);
  if (write_.is_response_error()) {
    SC_REPORT_FATAL(name(), ("bus write to 0x" + [&] {
                               char b[32];
                               std::snprintf(b, sizeof b, "%llx", (unsigned long long)address);
                               return std::string(b);
                             }() + " failed: " + write_.get_response_string()).c_str());
  }
  clock_.advance_to(sim + delay);
}

template <typename T>
int Gpp<T>::full_fifo() const {
  if (arch_.fifo_depth == 0) return -1;
  for (int i = 0; i < fifos.size(); ++i)
    if (!fifos[i]->has_space()) return i;
  return -1;
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
sc_time Gpp<T>::room_time() const {
  sc_time t = clock_.now();
  if (arch_.fifo_depth == 0) return t;
  for (int i = 0; i < fifos.size(); ++i) t = std::max(t, fifos[i]->space_time());
  return t;
}

template <typename T>
void Gpp<T>::trace_in_flight() {
  if (vcd_) vcd_->change(vcd_in_flight_, clock_.now().value(), issued_ - retired_);
}

template <typename T>
void Gpp<T>::issue(std::uint32_t id) {
  clock_.advance_to(room_time());  // as at `at`: room first, then the ray is generated
  const sc_time start = clock_.now();
  clock_.advance(cycle_ * static_cast<double>(arch_.gpp.cycles_per_ray));
  if (timeline_) timeline_->slice(track_, "issue", start.value(), clock_.now().value(), {{"ray", id}});
  pending_[id].answers_left = units_;
  ++issued_;
  ++stats_.rays[static_cast<int>(frame_.rays[id].kind)];
  trace_in_flight();
  RayPacket<T> packet{id, &frame_.rays[id]};
  write(addr::broadcast_rays, &packet, Bytes<T>::ray_bytes(arch_.top_tree()));
}

template <typename T>
void Gpp<T>::hit_transport(tlm::tlm_generic_payload& p, sc_time& delay) {
  const auto* a = reinterpret_cast<const AnswerPacket<T>*>(p.get_data_ptr());
  if (p.get_command() != tlm::TLM_WRITE_COMMAND || a->ray >= pending_.size() || !pending_[a->ray].answers_left) {
    p.set_response_status(tlm::TLM_GENERIC_ERROR_RESPONSE);
    return;
  }
  Pending& r = pending_[a->ray];
  r.occluded = r.occluded || a->occluded;
  if (a->hit.valid() && closer(a->hit, r.hit)) r.hit = a->hit;
  completed_at_[a->ray] = std::max(completed_at_[a->ray], sc_time_stamp() + delay);
  if (--r.answers_left == 0) {
    completed_.push({completed_at_[a->ray], a->ray});
    // Wake the GPP only if it waits for something later than this completion (a unit
    // running ahead answers long before the answer is due; the GPP's deadline covers it).
    if (completed_at_[a->ray] < wake_before_) answered_.notify();
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
  ++retired_;
  if (rec.kind == RayKind::primary) {
    if (progress_ && (++primaries_retired_ & 4095) == 0) progress_(primaries_retired_, pixel_count_);
    const std::uint32_t p = rec.pixel;
    // The merged answers must be the traced nearest hit: the units' answers are the
    // functional work's, so anything else is a fault in the model's plumbing.
    if (pr.hit.valid() != (frame_.image.object[p] != kNone) ||
        (pr.hit.valid() && (pr.hit.object != frame_.image.object[p] || pr.hit.prim != frame_.image.prim[p] ||
                            static_cast<float>(pr.hit.t) != frame_.image.z[p])))
      SC_REPORT_FATAL(name(), ("ray " + std::to_string(id) + ": the units' answers disagree with the functional trace").c_str());
    if (!pr.hit.valid()) {
      finish_pixel(p, img);
    } else {
      const sc_time start = clock_.now();
      clock_.advance(cycle_ * static_cast<double>(arch_.gpp.cycles_per_hit));
      if (timeline_) timeline_->slice(track_, "shade", start.value(), clock_.now().value(), {{"ray", id}});
      img.z[p] = static_cast<float>(pr.hit.t);
      img.object[p] = pr.hit.object;
      img.prim[p] = pr.hit.prim;
      const std::uint32_t first = id + 1, end = frame_.pixel_rays[p + 1];
      shadow_left_[p] = end - first;
      for (std::uint32_t s = first; s < end; ++s) shadow_queue_.push_back(s);
      if (first == end) finish_pixel(p, img);
    }
  } else if (--shadow_left_[rec.pixel] == 0) {
    finish_pixel(rec.pixel, img);
  }
  trace_in_flight();
}

// Object memories hold the geometry of their unit's spheres. Before the animation the
// set-up command loads every memory, outside any frame. When a later frame's
// assignment moves spheres, the geometry a unit gains is written into its memory over the
// bus before the frame's rays: that transfer is part of the frame. Non-rigid (deforming)
// spheres are rewritten every frame.
// A unit whose spheres exceed its memory's capacity (memory.sram_bytes) reads them from
// DRAM through its memory, now a cache (cache.h): DRAM holds the whole scene from the
// set-up on, so nothing moves when its spheres change; deforming geometry is rewritten in
// DRAM, and dropped from every cache.
template <typename T>
void Gpp<T>::load_memories() {
  loaded_.resize(assignment_.size());
  cached_.resize(assignment_.size(), 0);
  std::vector<std::pair<std::uint64_t, std::uint64_t>> rewritten;
  const GeometryAddresses<T> at(geom_);
  for (std::uint32_t s = 0; s < geom_.sphere_count(); ++s)
    if (geom_.deforming[s] && arch_.memory.sram_bytes) {
      rewritten.push_back(at.triangles_of(geom_, s));
      rewritten.push_back(at.nodes_of(geom_, s));
    }
  for (std::size_t u = 0; u < assignment_.size(); ++u) {
    const bool cache = memory_is_cache(arch_, assigned_bytes(geom_, assignment_[u]));
    std::uint64_t bytes = 0;
    for (std::uint32_t s : assignment_[u])
      if (geom_.deforming[s] ||
          (!cache && (cached_[u] || std::find(loaded_[u].begin(), loaded_[u].end(), s) == loaded_[u].end())))
        bytes += geom_.memory_bytes(s);  // triangles, and nodes with a BVH
    if (loaded_[u] == assignment_[u] && cache == static_cast<bool>(cached_[u]) && bytes == 0) continue;
    MemoryLoadPacket packet{assignment_[u], cache, cache ? rewritten : decltype(rewritten){}};
    cached_[u] = cache ? 1 : 0;
    stats_.memory_load_bytes += bytes;
    stats_.unit_memory_load_bytes.resize(assignment_.size(), 0);
    stats_.unit_memory_load_bytes[u] += bytes;
    const sc_time before = clock_.now();
    write(addr::iu_window(static_cast<int>(u)) + addr::iu_memory, &packet, static_cast<unsigned>(bytes));
    stats_.memory_load_cycles += static_cast<std::uint64_t>((clock_.now() - before) / cycle_ + 0.5);
    loaded_[u] = assignment_[u];
  }
}

template <typename T>
void Gpp<T>::render_frame(const FrameCommand& cmd) {
  stats_ = GppStats{};
  stats_.start = clock_.now();
  load_memories();  // geometry that moved or deforms (the set-up command loaded the rest)
  if (vcd_) vcd_->change(vcd_frame_, stats_.start.value(), static_cast<std::uint64_t>(cmd.frame));
  const FrameSetup<T> setup = setup_frame(scene_, geom_, cmd.frame, cmd.to_world, cmd.camera);

  // Configuration registers: each unit's spheres, world spheres and matrices, and with
  // --top bvh its tree over them, refitted to the frame by the GPP (rebuilt first where the
  // unit's spheres changed; building, like choosing the assignment, is not charged).
  units_ = static_cast<unsigned>(assignment_.size());
  registers_.resize(units_);
  trees_.resize(arch_.top_tree() ? units_ : 0);
  for (unsigned u = 0; u < units_; ++u) {
    registers_[u].load(setup, geom_, assignment_[u]);
    if (arch_.top_tree())
      stats_.refit_nodes += load_top(registers_[u], trees_[u], assignment_[u], setup, geom_, &stats_.built_nodes);
  }
  if (stats_.refit_nodes) {
    stats_.refit_cycles = stats_.refit_nodes * static_cast<std::uint64_t>(arch_.gpp.cycles_per_node);
    const sc_time start = clock_.now();
    if (vcd_) vcd_->change(vcd_refit_, start.value(), 1);
    clock_.advance(cycle_ * static_cast<double>(stats_.refit_cycles));
    if (vcd_) vcd_->change(vcd_refit_, clock_.now().value(), 0);
    if (timeline_) timeline_->slice(track_, "refit", start.value(), clock_.now().value(), {{"nodes", stats_.refit_nodes}});
  }
  for (unsigned u = 0; u < units_; ++u) {
    ConfigPacket<T> packet{&registers_[u], cached_[u] != 0};
    const unsigned bytes = static_cast<unsigned>(assignment_[u].size()) * Bytes<T>::sphere_config +
                           static_cast<unsigned>(registers_[u].top.size()) * Bytes<T>::top_node;
    stats_.config_bytes += bytes;
    write(addr::iu_window(static_cast<int>(u)) + addr::iu_config, &packet, bytes);
  }

  // The frame's functional work, on every thread the pool allows (functional_frame.h).
  const CameraRays camera(cmd.camera, cmd.width, cmd.height);
  const Shader<T> shader(scene_, setup);
  try {
    // The records' detail for the waveform's phases, and for caches, which time each visit.
    const bool caches = std::find(cached_.begin(), cached_.end(), 1) != cached_.end();
    trace_functional(frame_, geom_, registers_, camera, shader, arch_, cmd.width, cmd.height,
                     vcd_ != nullptr || timeline_ != nullptr || caches || arch_.iu.model == IuModel::pipelined);
  } catch (const Interrupted&) {  // SIGINT / SIGTERM: abandon the frame; the testbench says what completed
    sc_stop();
    wait(abandoned_);  // never notified
  }

  const std::size_t pixels = static_cast<std::size_t>(cmd.width) * cmd.height;
  pending_.assign(frame_.ray_count(), Pending{});
  completed_at_.assign(frame_.ray_count(), SC_ZERO_TIME);
  shadow_left_.assign(pixels, 0);
  completed_ = {};
  shadow_queue_.clear();
  issued_ = retired_ = 0;
  primaries_retired_ = 0;
  pixel_count_ = pixels;
  std::size_t next_pixel = 0;
  // The GPP's next work item, at either level: the earlier of (a) handling an answered
  // ray, due when its last answer arrived, and (b) writing the next ray (a shadow ray
  // first), possible once every FIFO has room; on a tie (a), as at `at`. At `at` both are
  // always due by the time the GPP looks. Under temporal decoupling either can lie in the
  // GPP's future: a unit running ahead answers, or pops, early in simulation order. The
  // GPP then does not jump its clock to that time (it would handle that answer before
  // answers due earlier that lagging units have yet to send, and hold back every ray it
  // would have written meanwhile) but waits in simulation time until it is due, or until
  // something earlier turns up.
  const sc_time never = sc_max_time();
  for (;;) {
    if (stop_signal()) {  // SIGINT / SIGTERM: abandon the frame; the testbench says what completed
      sc_stop();
      wait(abandoned_);  // never notified
    }
    const bool work = !shadow_queue_.empty() || next_pixel < pixels;
    const bool room = work && full_fifo() < 0;
    const sc_time due = completed_.empty() ? never : completed_.top().at;
    const sc_time ready = room ? room_time() : never;
    const sc_time next = std::min(due, ready);
    if (next == never && !work && retired_ == issued_) break;
    if (next <= clock_.now()) {
      if (due <= ready) {
        const std::uint32_t id = completed_.top().ray;
        completed_.pop();
        retire(id, cmd);
      } else if (!shadow_queue_.empty()) {
        const std::uint32_t id = shadow_queue_.front();
        shadow_queue_.pop_front();
        issue(id);
      } else {
        issue(frame_.pixel_rays[next_pixel++]);
      }
      continue;
    }
    wait_for_space_or_answers(work && !room, next == never ? nullptr : &next);
  }
  stats_.end = clock_.now();
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
