// Dram: the memory behind the units' object memories when they are caches (cache.h) and
// their misses contend: channels shared by several units (memory.dram.units_per_channel >
// 1), or misses over the shared bus (memory.dram.path "bus"); the engine instantiates it
// then. With memory.dram.path "external" the misses leave the engine through its memory
// port (engine.h `mem`), and the oprt command binds one of these there (testbench.cpp).
// It holds the whole scene's geometry from addr::dram_base on and serves cache line fills.
// (An object memory with a channel of its own times its fills itself:
// timing/object_memory_model.h.)
//
// Timing. Units share channels, units_per_channel each (unit u on channel u / k). A channel
// moves one line at a time, line_bytes / bytes_per_cycle cycles, granted first come first
// served by request time (a calendar, calendar.h); the line arrives latency_cycles after
// its transfer is granted, plus the transfer. The channel never waits: it annotates the
// arrival. Requests reach it in time order when the object memories synchronise before
// each miss (intersection_unit.cpp decides when), and then the calendar is FCFS exactly.
#pragma once

#include "arch/arch.h"
#include "timing/calendar.h"

#include <cstdint>
#include <vector>

#include <systemc>
#include <tlm>
#include <tlm_utils/multi_passthrough_target_socket.h>

namespace oprt::hw {

using timing::Calendar;

class Dram : public sc_core::sc_module {
 public:
  tlm_utils::multi_passthrough_target_socket<Dram> in;  // line fills

  // `base`: the address a fill of the geometry's first byte carries (0 behind the bus, which
  // takes off its window; addr::dram_base on the engine's memory port).
  Dram(const sc_core::sc_module_name& name, const Arch& arch, std::size_t units, std::uint64_t base = 0);

  std::uint64_t bytes() const { return bytes_; }
  void reset_stats() { bytes_ = 0; }

 private:
  void b_transport(int from, tlm::tlm_generic_payload& p, sc_core::sc_time& delay);

  const sc_core::sc_time cycle_, latency_, transfer_;
  const std::uint32_t units_per_channel_;
  const std::uint64_t base_;
  std::vector<Calendar<sc_core::sc_time>> channels_;
  std::uint64_t bytes_ = 0;
};

}  // namespace oprt::hw
