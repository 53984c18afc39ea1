// The ray-triangle kernels an intersection unit can run. Each has its own object-memory
// format, its own exit stages and its own cycle schedule (arch/cycle_schedule.cpp); the
// block functions of geom/triangle_soa.h are the one place that dispatches on it.
#pragma once

#include <cstdint>
#include <optional>
#include <string>

namespace oprt {

enum class Kernel : std::uint8_t {
  moller = 0,      // Moller-Trumbore with a stored normal (geom/triangle.h)
  watertight = 1,  // Woop, Benthin and Wald, JCGT 2013 (geom/watertight.h)
};
constexpr int kKernels = 2;

// Every kernel leaves a test at one of four exit stages, numbered in its schedule's order;
// the work counts and the cost tables are indexed by that number.
constexpr int kTriStages = 4;

inline const char* to_string(Kernel k) { return k == Kernel::watertight ? "watertight" : "moller"; }

inline std::optional<Kernel> kernel_named(const std::string& name) {
  if (name == "moller") return Kernel::moller;
  if (name == "watertight") return Kernel::watertight;
  return std::nullopt;
}

// The exit stages' names, in order.
inline const char* const* stage_names(Kernel k) {
  static const char* const moller[kTriStages] = {"det", "u", "v", "t"};
  static const char* const watertight[kTriStages] = {"uv", "w", "det", "t"};
  return k == Kernel::watertight ? watertight : moller;
}

}  // namespace oprt
