// libFuzzer target: the glTF 2.0 loader. The same input is read as .gltf (JSON) and as .glb
// (the binary container; a file starting with the glTF magic is read as binary whatever
// its extension).
#include "fuzz_input.h"
#include "fuzz_scene.h"
#include "scene/load.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  auto load = [](const std::string& p) { oprt::fuzz::exercise(oprt::load_gltf(p)); };
  oprt::fuzz::run(data, size, "scene.gltf", load);
  return oprt::fuzz::run(data, size, "scene.glb", load);
}
