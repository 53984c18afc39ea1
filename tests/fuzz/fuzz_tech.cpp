// libFuzzer target: the oprt-tech/1 technology table (docs/tech-format.md), and the area and
// one frame's energy it gives a two-unit design at extreme but possible sizes and counts:
// every figure is finite or the table is refused (an InputError naming it).
#include "fuzz_input.h"
#include "cost/cost_model.h"
#include "cost/tech.h"

#include <cstdint>

namespace {
void exercise(const oprt::Tech& t) {
  using namespace oprt;
  Design d;
  d.units.resize(2);
  d.ray_bytes = ray_bytes(false);
  d.units[0] = {std::uint64_t{1} << 40, std::uint64_t{1} << 30, 4096, 0};  // 1 TiB of object memory
  d.units[1] = {64, 1, 1, 0};
  FrameActivity f;
  f.units.resize(2);
  for (UnitActivity& a : f.units) {
    a.work.sphere_tests = a.work.transforms = a.work.tri_stage[3] = std::uint64_t{1} << 40;
    a.memory_read_bytes = a.dram_bytes = a.fifo_pushes = a.fifo_pops = std::uint64_t{1} << 40;
  }
  f.bus_bytes = std::uint64_t{1} << 40;
  f.frame_time_s = 1e6;
  (void)area_mm2(t, d).to_json().dump();
  (void)frame_energy_j(t, d, op_counts(Kernel::moller), f).to_json().dump();
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return oprt::fuzz::run(data, size, "tech.json", [](const std::string& p) { exercise(oprt::load_tech(p)); });
}
