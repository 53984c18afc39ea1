// libFuzzer target: the oprt-scene/1 JSON loader (docs/scene-format.md).
#include "fuzz_input.h"
#include "fuzz_scene.h"
#include "scene/load.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  oprt::scene_limits.triangles = oprt::fuzz::kTriangleLimit;
  return oprt::fuzz::run(data, size, "scene.json",
                         [](const std::string& p) { oprt::fuzz::exercise(oprt::load_oprt_json(p)); });
}
