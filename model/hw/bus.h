// Bus: the shared interconnect between the GPP and the intersection units. It decodes the
// address map (payloads.h): each unit's configuration registers, object memory window and
// ray FIFO, the broadcast ray region (one write, delivered to every FIFO), and the GPP's
// hit port; any other address is answered with TLM_ADDRESS_ERROR_RESPONSE.
//
// Timing. `ideal`: transfers take no time and never contend (the paper's assumption).
// `shared`: one transfer at a time, each occupying the bus for arbitration_cycles +
// ceil(bytes / bytes_per_cycle) cycles, granted first come first served by request time.
// The arbiter keeps a calendar of granted intervals (calendar.h). At `at` requests arrive
// in time order, the calendar reduces to FCFS exactly, and the initiator waits out its
// transfer inside b_transport.
//
// Under temporal decoupling (`lt`) a request carries its initiator's local time, which may
// be ahead of simulation time, so requests can reach the bus out of time order. How that is
// handled is bus.lt_arbitration (arch.h):
//   sync      (default) the initiators synchronise before each transfer on this bus (gpp.cpp,
//             intersection_unit.cpp), so requests arrive in time order and are granted as at
//             `at`; computation between transfers stays decoupled.
//   calendar  requests arrive up to a quantum ahead; a late-arriving earlier request takes
//             the first gap at or after its own time. Cheaper, but when requests conflict
//             the one that arrived first in simulation keeps its slot: an initiator running
//             ahead gains priority it would not have at `at` (measured: docs/results.md).
//   busy_until  the naive arbiter: every request queues behind the latest grant, which
//             overstates contention by up to a quantum per transfer. Kept to show that.
#pragma once

#include "arch/arch.h"
#include "timing/calendar.h"
#include "trace/timeline.h"
#include "trace/vcd_writer.h"

#include <cstdint>
#include <vector>

#include <systemc>
#include <tlm>
#include <tlm_utils/multi_passthrough_initiator_socket.h>
#include <tlm_utils/multi_passthrough_target_socket.h>

namespace oprt::hw {

using timing::Arbiter;

class Bus : public sc_core::sc_module {
 public:
  tlm_utils::multi_passthrough_target_socket<Bus> in;      // from the GPP and the units
  tlm_utils::multi_passthrough_initiator_socket<Bus> out;  // to the targets, by map index

  Bus(const sc_core::sc_module_name& name, const Arch& arch, bool decoupled, VcdWriter* vcd,
      TimelineWriter* timeline = nullptr);

  // [base, base + size) goes to out[targets...]; more than one target is a multicast, to
  // every target, or (`masked`) to those whose bit is set in the unit mask that ends the
  // transfer's bytes (bit i: targets[i]). `what` names its transfers in the timeline.
  void map(std::uint64_t base, std::uint64_t size, std::vector<int> targets, const char* what = "transfer",
           bool masked = false);

  std::uint64_t busy_cycles() const { return busy_cycles_; }
  std::uint64_t transfers() const { return transfers_; }
  std::uint64_t bytes() const { return bytes_; }
  void reset_stats() { busy_cycles_ = transfers_ = bytes_ = 0; }

 private:
  struct Region {
    std::uint64_t base, size;
    std::vector<int> targets;
    const char* what;
    bool masked;
  };
  void b_transport(int from, tlm::tlm_generic_payload& p, sc_core::sc_time& delay);

  const bool shared_, decoupled_;
  const Arch& arch_;
  const sc_core::sc_time cycle_;
  std::vector<Region> regions_;
  std::size_t last_ = ~std::size_t{0};  // index of the region the last transfer went to
  Arbiter<sc_core::sc_time> arbiter_;
  std::uint64_t busy_cycles_ = 0, transfers_ = 0, bytes_ = 0;
  VcdWriter* vcd_;
  int vcd_busy_ = -1;
  TimelineWriter* timeline_;  // null when not traced
  int track_ = -1;
};

}  // namespace oprt::hw
