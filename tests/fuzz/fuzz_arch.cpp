// libFuzzer target: the oprt-arch/1 architecture file (docs/architecture-format.md), and
// the resolved architecture written back as JSON (what stats.json records).
#include "fuzz_input.h"
#include "arch/arch.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return oprt::fuzz::run(data, size, "arch.json",
                         [](const std::string& p) { (void)oprt::to_json(oprt::load_arch(p)).dump(); });
}
