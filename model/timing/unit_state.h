// What a serial intersection unit is doing, as its waveform shows it (a 3-bit state) and its
// timeline names it.
#pragma once

#include <cstdint>

namespace oprt::timing {

enum class UnitState : std::uint8_t { idle = 0, sphere = 1, transform = 2, primitive = 3, stall = 4, box = 5, node = 6 };

inline const char* to_string(UnitState s) {
  constexpr const char* kName[] = {"idle", "sphere", "transform", "primitive", "stall", "box", "node"};
  return kName[static_cast<int>(s)];
}

}  // namespace oprt::timing
