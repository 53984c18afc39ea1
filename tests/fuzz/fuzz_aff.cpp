// libFuzzer target: the BART .aff loader (model/scene/aff.h).
#include "fuzz_input.h"
#include "fuzz_scene.h"
#include "scene/aff.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return oprt::fuzz::run(data, size, "scene.aff",
                         [](const std::string& p) { oprt::fuzz::exercise(oprt::load_aff(p)); });
}
