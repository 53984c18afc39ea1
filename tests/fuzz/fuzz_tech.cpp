// libFuzzer target: the oprt-tech/1 technology table (docs/tech-format.md), and the area and
// energy it gives (fuzz_tech.h).
#include "fuzz_input.h"
#include "fuzz_tech.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return oprt::fuzz::run(data, size, "tech.json", [](const std::string& p) { oprt::fuzz::exercise(oprt::load_tech(p)); });
}
