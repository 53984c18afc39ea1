// Bus: the shared interconnect between the GPP and the intersection units. It decodes the
// address map (payloads.h): each unit's configuration registers, object memory window and
// ray FIFO, the broadcast ray region (one write, delivered to every FIFO), and the GPP's
// hit port; any other address is answered with TLM_ADDRESS_ERROR_RESPONSE.
//
// Timing. `ideal`: transfers take no time and never contend (the paper's assumption).
// `shared`: one transfer at a time, each occupying the bus for arbitration_cycles +
// ceil(bytes / bytes_per_cycle) cycles, granted first come first served by request time.
// The arbiter keeps a calendar of granted intervals rather than a single "busy until"
// time: under temporal decoupling requests reach it out of time order (a unit running
// ahead asks before an earlier request from a unit that is behind), and a late-arriving
// earlier request is slotted into the first gap at or after its own time instead of being
// queued behind every reservation made so far, which would overstate contention by up to
// a quantum per transfer. At `at` requests arrive in time order and the calendar reduces
// to FCFS exactly; the initiator waits out its transfer inside b_transport. (bus.arbiter =
// "busy_until" replaces the calendar by the naive single busy-until time, to measure the
// error the calendar avoids; see docs/results.md.)
#pragma once

#include "hw/arch.h"
#include "hw/calendar.h"
#include "hw/vcd_writer.h"

#include <cstdint>
#include <vector>

#include <systemc>
#include <tlm>
#include <tlm_utils/multi_passthrough_initiator_socket.h>
#include <tlm_utils/multi_passthrough_target_socket.h>

namespace oprt::hw {

class Bus : public sc_core::sc_module {
 public:
  tlm_utils::multi_passthrough_target_socket<Bus> in;      // from the GPP and the units
  tlm_utils::multi_passthrough_initiator_socket<Bus> out;  // to the targets, by map index

  Bus(const sc_core::sc_module_name& name, const Arch& arch, bool decoupled, VcdWriter* vcd);

  // [base, base + size) goes to out[targets...]; more than one target is a multicast.
  void map(std::uint64_t base, std::uint64_t size, std::vector<int> targets);

  std::uint64_t busy_cycles() const { return busy_cycles_; }
  std::uint64_t transfers() const { return transfers_; }
  std::uint64_t bytes() const { return bytes_; }
  void reset_stats() { busy_cycles_ = transfers_ = bytes_ = 0; }

 private:
  struct Region {
    std::uint64_t base, size;
    std::vector<int> targets;
  };
  void b_transport(int from, tlm::tlm_generic_payload& p, sc_core::sc_time& delay);

  const bool shared_, decoupled_;
  const int bytes_per_cycle_, arbitration_cycles_;
  const sc_core::sc_time cycle_;
  std::vector<Region> regions_;
  Arbiter<sc_core::sc_time> arbiter_;
  std::uint64_t busy_cycles_ = 0, transfers_ = 0, bytes_ = 0;
  VcdWriter* vcd_;
  int vcd_busy_ = -1;
};

}  // namespace oprt::hw
