// Gpp: the general-purpose processor. Per frame it takes the objects' matrices from the
// host, computes each sphere's world position and each object's world -> local matrix and
// writes every unit's configuration registers; it generates the primary rays and writes each
// one, broadcast, into every unit's ray FIFO; it collects every unit's answer to a ray,
// keeps the nearest hit, shades it (Phong) and issues the shadow rays; the frame ends when
// every ray has retired.
//
// Its rules are the plan's (timing/gpp_plan.h, shared with the analytic level): what each
// object memory loads, the registers and the refit of the units' trees, the frame's
// functional trace, and the order of its work: handling a ray whose answers are all in
// (cycles_per_hit for a primary hit), issuing a pending shadow ray, issuing the next primary
// ray (cycles_per_ray each). This module spends the time: it starts a ray write only when
// every ray FIFO has room, so a full FIFO never holds the bus; it merges the answers the
// units send and checks each merged answer against the trace.
#pragma once

#include "arch/arch.h"
#include "ref/functional_frame.h"
#include "timing/gpp_plan.h"
#include "timing/gpp_recipe.h"
#include "timing/unit_run.h"
#include "hw/local_clock.h"
#include "hw/extensions.h"
#include "hw/ray_fifo.h"
#include "trace/timeline.h"
#include "trace/vcd_writer.h"
#include "hw/watchdog.h"
#include "ref/image.h"
#include "ref/shading.h"

#include <functional>
#include <memory>
#include <vector>

#include <systemc>
#include <tlm>
#include <tlm_utils/simple_initiator_socket.h>
#include <tlm_utils/simple_target_socket.h>

namespace oprt::hw {

using timing::FrameCommand, timing::GppFigures, timing::GppPhase, timing::GppPlan, timing::GppWork, timing::MemoryLoad,
    timing::RayWrites, timing::Waiting;

// The frame's figures (timing/unit_run.h GppFigures: rays, geometry loaded and its wait, the
// refit), and the times and counts only this module has.
struct GppStats : GppFigures {
  sc_core::sc_time start, end;           // the frame's first config write and last retirement
  sc_core::sc_time started;              // the end of its start: its loads, refit and registers done
  std::uint64_t config_bytes = 0;
  std::uint64_t route_cycles = 0;  // --route: the router's, on the GPP's timeline
  std::vector<std::uint64_t> unit_memory_load_bytes;  // per unit: its share of memory_load_bytes
  Waiting<sc_core::sc_time> waiting;  // what rays waiting for their parents' answers cost (gpp_plan.h)
};

template <typename T>
class Gpp : public sc_core::sc_module, public Waiter {
 public:
  tlm_utils::simple_target_socket<Gpp> host;   // frame commands
  tlm_utils::simple_target_socket<Gpp> hits;   // answers from the units (via the bus)
  tlm_utils::simple_initiator_socket<Gpp> bus; // configuration writes and rays
  sc_core::sc_port<RayFifoIf, 0> fifos;        // every ray FIFO's full flag

  SC_HAS_PROCESS(Gpp);
  Gpp(const sc_core::sc_module_name& name, const Scene& scene, const SceneGeometry<T>& geometry, const Arch& arch,
      FunctionalFrame<T>& frame, VcdWriter* vcd, TimelineWriter* timeline = nullptr);

  // Spheres per unit, in the units' order; takes effect at the next frame.
  void set_assignment(const std::vector<std::vector<std::uint32_t>>& unit_spheres) { plan_.assign(unit_spheres); }
  const GppStats& stats() const { return stats_; }
  const GppPlan<T>& plan() const { return plan_; }
  // Called now and then during a frame with (primary rays retired, pixels): for progress bars.
  void on_progress(std::function<void(std::uint64_t, std::uint64_t)> f) { progress_ = std::move(f); }
  std::string waiting_for() const override;

  // The recipe's clock (timing/gpp_clock.h), called by its steps only (timing/gpp_recipe.h).
  void compute(GppPhase phase, std::uint64_t cycles);
  void load(const MemoryLoad& l);
  void write_config(std::uint32_t unit, std::uint64_t bytes);
  void generated(std::uint32_t id);
  void routed_nowhere(std::uint32_t id);
  template <typename Wave>
  void write_rays(std::uint32_t id, const Wave& wave, const RayWrites& w);

 private:
  struct Pending {  // a ray waiting for answers
    std::uint32_t answers_left = 0;
    bool occluded = false;
    HitRecord<T> hit;
  };

  void run();
  void host_transport(tlm::tlm_generic_payload& p, sc_core::sc_time& delay);
  void hit_transport(tlm::tlm_generic_payload& p, sc_core::sc_time& delay);
  void render_frame(const FrameCommand& cmd);
  void write(tlm::tlm_generic_payload& p);
  // f(i) for each FIFO that ray `id`'s next wave is written to (every one when broadcast).
  template <typename F>
  void for_wave_fifos(std::uint32_t id, F&& f) const;
  int full_fifo() const;  // index of a full ray FIFO the next write goes to, or -1
  void wait_for_space_or_answers(bool want_space, const sc_core::sc_time* deadline);
  sc_core::sc_time room_time(std::uint32_t id) const;  // when ray `id`'s next wave has room
  void issue(std::uint32_t ray);
  void retire(std::uint32_t ray, const FrameCommand& cmd);
  void finish_pixel(std::uint32_t pixel, FrameImage& image) const;
  void trace_in_flight();

  const Scene& scene_;
  const SceneGeometry<T>& geom_;
  const Arch& arch_;
  FunctionalFrame<T>& frame_;
  const sc_core::sc_time cycle_;
  GppPlan<T> plan_;
  LocalClock clock_;
  const bool sync_on_bus_;
  GppStats stats_;

  // Frame state.
  const FrameCommand* command_ = nullptr;
  sc_core::sc_event request_, done_, answered_, abandoned_;
  sc_core::sc_time wake_before_;  // while waiting for answers: a completion before this wakes the GPP
  std::vector<Pending> pending_;
  std::vector<std::uint32_t> rays_left_;  // per pixel: rays of its tree not yet retired
  std::unique_ptr<GppWork<T, sc_core::sc_time>> work_;
  std::vector<sc_core::sc_time> completed_at_;  // per ray: when its last answer arrived
  std::uint64_t issued_ = 0, retired_ = 0;
  unsigned units_ = 0;
  tlm::tlm_generic_payload ray_, config_, load_;  // a payload per purpose (extensions.h)
  ByteBuffer ray_bytes_, bulk_bytes_;
  std::function<void(std::uint64_t, std::uint64_t)> progress_;
  std::uint64_t primaries_retired_ = 0, pixel_count_ = 0;
  VcdWriter* vcd_;
  int vcd_in_flight_ = -1, vcd_frame_ = -1, vcd_kind_ = -1, vcd_refit_ = -1, vcd_routing_ = -1, vcd_fanout_ = -1;
  TimelineWriter* timeline_;  // null when not traced
  int track_ = -1, router_track_ = -1;
  std::uint32_t current_ray_ = 0;  // the ray being issued or retired (the timeline names it)
  // For the watchdog (plain stores): in a frame, and what it waits for (-1: answers only,
  // else also room in that FIFO).
  bool in_frame_ = false;
  int waiting_on_fifo_ = -1;
};

extern template class Gpp<float>;
extern template class Gpp<double>;
static_assert(timing::is_gpp_clock_v<Gpp<float>> && timing::is_gpp_clock_v<Gpp<double>>,
              "the SystemC GPP is the recipe's clock (timing/gpp_clock.h)");

}  // namespace oprt::hw
