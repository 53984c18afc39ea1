// Engine: the top of the hardware model. It instantiates the GPP, the bus, and for every
// unit the assignment uses (min(units requested, spheres)) an intersection unit (serial or
// pipelined) with its ray FIFO and object memory, and DRAM when object memories share its
// channels or reach it over the bus; it binds them; all binding happens here.
//
//   host --> Gpp.host
//   Gpp.bus, IntersectionUnit[i].bus --> Bus.in
//   Bus.out[0] --> Gpp.hits
//   Bus.out[1 + 3i] --> IntersectionUnit[i].cfg
//   Bus.out[2 + 3i] --> ObjectMemory[i].load
//   Bus.out[3 + 3i] --> RayFifo[i].in              (and the broadcast region: every RayFifo)
//   IntersectionUnit[i].mem --> ObjectMemory[i].read;  IntersectionUnit[i].fifo --> RayFifo[i]
//   ObjectMemory[i].fill --> Dram.in               (shared channels: memory.dram.path "channel"), or
//   ObjectMemory[i].fill --> Bus.in; Bus.out[1 + 3 units] --> Dram.in   ("bus"), or
//   ObjectMemory[i].fill --> Engine.fills; Engine.mem --> the platform's memory   ("external")
//
// The memory port `mem` (memory.dram.path "external"): the object memories' cache line fills
// leave the engine there, one blocking TLM read per line: data_length
// memory.cache.line_bytes, address addr::dram_base + the line's address in the scene's
// geometry (docs/architecture-format.md, "The memory port"), a FillExtension naming the
// unit. The target adds its latency to the annotated delay: the line is in the object
// memory when the delay it returns has passed. A request is made at sc_time_stamp() + its
// delay; requests reach the port in time order only where the units synchronise before each
// miss (serial units with memory.dram.units_per_channel > 1, as for shared channels); a
// memory that arbitrates between units otherwise orders them itself, as hw/dram.h does with
// a calendar per channel. Bind it before simulation starts whenever memory.sram_bytes is
// set; the oprt command binds its own DRAM model (hw/dram.h) there. Other paths leave it
// unbound.
#pragma once

#include "balance/assign.h"
#include "hw/bus.h"
#include "hw/dram.h"
#include "hw/gpp.h"
#include "hw/intersection_unit.h"
#include "hw/pipelined_unit.h"
#include "hw/serial_unit.h"
#include "hw/object_memory.h"
#include "hw/ray_fifo.h"

#include <memory>
#include <vector>

#include <systemc>
#include <tlm_utils/multi_passthrough_target_socket.h>
#include <tlm_utils/simple_initiator_socket.h>

namespace oprt::hw {

using timing::FrameCommand;

template <typename T>
class Engine : public sc_core::sc_module {
 public:
  tlm_utils::simple_initiator_socket<Engine> host;  // the testbench's frame commands go here
  tlm_utils::simple_initiator_socket_optional<Engine> mem;  // cache line fills to the platform's memory ("external")

  Engine(const sc_core::sc_module_name& name, const Scene& scene, const SceneGeometry<T>& geometry, const Arch& arch,
         std::size_t units, VcdWriter* vcd, TimelineWriter* timeline = nullptr);

  // Run one frame to completion; call from an SC_THREAD (the testbench's).
  void run_frame(FrameCommand& cmd);
  // Before the first frame: load the object memories (not part of any frame).
  void setup();
  // Spheres per unit for the next frames (assignment.units() must equal units()).
  void assign(const Assignment& a);
  // The frame just run as the modules counted it, each unit's figures made from its work in
  // the functional trace (timing/unit_run.h); stops the simulation if a module waited out
  // other cycles, or read other bytes, than that work. Then reset_stats() for the next frame.
  timing::FrameRun figures();
  void reset_stats();

  std::size_t units() const { return units_.size(); }
  Gpp<T>& gpp() { return *gpp_; }
  Bus& bus() { return *bus_; }
  IntersectionUnit<T>& unit(std::size_t i) { return *units_[i]; }
  RayFifo& fifo(std::size_t i) { return *fifos_[i]; }
  ObjectMemory& memory(std::size_t i) { return *memories_[i]; }
  Dram* dram() { return dram_.get(); }  // null when no object memory needs it, or it is outside ("external")
  bool memory_port_used() const { return external_; }  // fills leave through `mem`: it must be bound
  const FunctionalFrame<T>& functional() const { return frame_; }

 private:
  void end_of_elaboration() override;
  // The object memories' fills, on their way to `mem`.
  void fill_transport(int from, tlm::tlm_generic_payload& p, sc_core::sc_time& delay);

  // Made only when used: an unbound target socket fails SystemC's binding check.
  std::unique_ptr<tlm_utils::multi_passthrough_target_socket<Engine>> fills_;
  bool external_ = false;
  FunctionalFrame<T> frame_;  // the frame's traced work: written by the GPP, read by the units
  const SceneGeometry<T>& geometry_;
  const Arch arch_;
  Assignment assignment_;
  std::unique_ptr<Gpp<T>> gpp_;
  std::unique_ptr<Bus> bus_;
  std::unique_ptr<Dram> dram_;
  std::vector<std::unique_ptr<IntersectionUnit<T>>> units_;
  std::vector<std::unique_ptr<RayFifo>> fifos_;
  std::vector<std::unique_ptr<ObjectMemory>> memories_;
  tlm::tlm_generic_payload command_;
  ByteBuffer command_bytes_;
};

extern template class Engine<float>;
extern template class Engine<double>;

}  // namespace oprt::hw
