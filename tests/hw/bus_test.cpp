// The bus on its own: address decoding, offsets, multicast, unmapped addresses, and the
// shared bus's occupancy by hand.
#include "hw/bus.h"
#include "hw/ray_fifo.h"

#include <catch2/catch.hpp>

#include <cstring>

#include <tlm_utils/simple_initiator_socket.h>
#include <tlm_utils/simple_target_socket.h>

using namespace oprt;
using namespace sc_core;

namespace {
struct Target : sc_module {
  tlm_utils::simple_target_socket<Target> in{"in"};
  std::vector<std::uint64_t> seen;
  std::vector<sc_time> at;
  explicit Target(const sc_module_name& n) : sc_module(n) { in.register_b_transport(this, &Target::b); }
  void b(tlm::tlm_generic_payload& p, sc_time& d) {
    seen.push_back(p.get_address());
    at.push_back(sc_time_stamp() + d);
    p.set_response_status(tlm::TLM_OK_RESPONSE);
  }
};

struct Initiator : sc_module {
  tlm_utils::simple_initiator_socket<Initiator> out{"out"};
  std::vector<tlm::tlm_response_status> status;
  std::vector<std::uint64_t> addresses;
  std::vector<unsigned> lengths;
  SC_HAS_PROCESS(Initiator);
  explicit Initiator(const sc_module_name& n) : sc_module(n) { SC_THREAD(run); }
  void run() {
    unsigned char data[64] = {};
    for (std::size_t i = 0; i < addresses.size(); ++i) {
      tlm::tlm_generic_payload p;
      p.set_command(tlm::TLM_WRITE_COMMAND);
      p.set_address(addresses[i]);
      p.set_data_ptr(data);
      p.set_data_length(lengths[i]);
      sc_time d = SC_ZERO_TIME;
      out->b_transport(p, d);
      status.push_back(p.get_response_status());
    }
  }
};
}  // namespace

TEST_CASE("bus: decodes the map and answers unmapped addresses with an address error", "[bus]") {
  Arch arch;
  arch.bus.model = BusModel::shared;
  arch.bus.bytes_per_cycle = 8;
  arch.bus.arbitration_cycles = 1;  // 100 MHz: 10 ns cycles
  hw::Bus bus("bus", arch, false, nullptr);
  Initiator ini("ini");
  Target a("a"), b("b");
  ini.out.bind(bus.in);
  bus.out.bind(a.in);
  bus.out.bind(b.in);
  bus.map(0x1000, 0x100, {0});
  bus.map(0x2000, 0x100, {1});
  bus.map(0x3000, 0x10, {0, 1});  // multicast
  ini.addresses = {0x1010, 0x2000, 0x3004, 0x1100, 0x0, 0x5000};
  ini.lengths = {8, 20, 8, 8, 8, 8};
  sc_start();
  REQUIRE(ini.status.size() == 6);
  CHECK(ini.status[0] == tlm::TLM_OK_RESPONSE);
  CHECK(ini.status[1] == tlm::TLM_OK_RESPONSE);
  CHECK(ini.status[2] == tlm::TLM_OK_RESPONSE);
  CHECK(ini.status[3] == tlm::TLM_ADDRESS_ERROR_RESPONSE);  // just past a region
  CHECK(ini.status[4] == tlm::TLM_ADDRESS_ERROR_RESPONSE);
  CHECK(ini.status[5] == tlm::TLM_ADDRESS_ERROR_RESPONSE);
  // Targets see offsets within their region; the multicast reached both.
  CHECK(a.seen == std::vector<std::uint64_t>{0x10, 0x4});
  CHECK(b.seen == std::vector<std::uint64_t>{0x0, 0x4});
  // Occupancy: 8 bytes -> 1 + 1 cycles, 20 bytes -> 1 + 3 cycles; back to back from t = 0.
  CHECK(a.at[0] == sc_time(20, SC_NS));
  CHECK(b.at[0] == sc_time(60, SC_NS));
  CHECK(a.at[1] == sc_time(80, SC_NS));
  CHECK(bus.busy_cycles() == 2 + 4 + 2);
  CHECK(bus.transfers() == 3);
}

namespace {
// Writes rays into a FIFO of depth 2 and pops them at times ahead of simulation time, as a
// temporally decoupled unit does; records when the FIFO says the next write's slot was freed.
struct FifoDriver : sc_module {
  tlm_utils::simple_initiator_socket<FifoDriver> out{"out"};
  hw::RayFifo& fifo;
  std::vector<sc_time> room;
  std::vector<bool> space;
  SC_HAS_PROCESS(FifoDriver);
  FifoDriver(const sc_module_name& n, hw::RayFifo& f) : sc_module(n), fifo(f) { SC_THREAD(run); }
  void write(std::uint32_t id) {
    unsigned char data[36] = {};
    std::memcpy(data, &id, 4);
    tlm::tlm_generic_payload p;
    p.set_command(tlm::TLM_WRITE_COMMAND);
    p.set_data_ptr(data);
    p.set_data_length(36);
    sc_time d = SC_ZERO_TIME;
    out->b_transport(p, d);
  }
  void look() {  // space_time() is asked only when there is room (the GPP's rule)
    space.push_back(fifo.has_space());
    room.push_back(space.back() ? fifo.space_time() : SC_ZERO_TIME);
  }
  void run() {
    write(1);
    write(2);
    look();  // full: no room
    hw::RayEntry e;
    fifo.pop(e, sc_time(100, SC_NS));  // ray 1 leaves at 100 ns, ahead of simulation time (0)
    look();  // the third write's slot is ray 1's: free from 100 ns
    write(3);
    fifo.pop(e, sc_time(150, SC_NS));
    look();  // the fourth write's slot is ray 2's: free from 150 ns
  }
};
}  // namespace

TEST_CASE("ray fifo: a write's slot is free from the pop that freed it, also for the first full FIFO", "[fifo]") {
  hw::RayFifo fifo("fifo", 2, nullptr);
  FifoDriver driver("driver", fifo);
  driver.out.bind(fifo.in);
  sc_start();
  REQUIRE(driver.room.size() == 3);
  CHECK(driver.space == std::vector<bool>{false, true, true});
  CHECK(driver.room[1] == sc_time(100, SC_NS));
  CHECK(driver.room[2] == sc_time(150, SC_NS));
}
