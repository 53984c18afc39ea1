// libFuzzer target: the OBJ mesh loader (a scene's {"obj": PATH} mesh).
#include "fuzz_input.h"
#include "scene/load.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  return oprt::fuzz::run(data, size, "mesh.obj", [](const std::string& p) { oprt::load_obj(p); });
}
