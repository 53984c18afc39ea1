// The clock the GPP's recipe (gpp_recipe.h) is written against: the one interface between the
// rules both clocks share and the two clocks, the SystemC GPP (hw/gpp.h: a local clock,
// transactions, waits) and the analytic GPP (analytic/gpp.h: a cycle count and calendars).
// A clock provides:
//   compute(GppPhase, cycles)          the GPP works this long (called only when cycles > 0)
//   load(const MemoryLoad&)            write a unit's geometry into its object memory
//   write_config(unit, bytes)          write a unit's configuration registers
//   generated(ray)                     a new ray has been generated (and routed)
//   routed_nowhere(ray)                the router answered the ray itself (no unit entered)
//   write_rays(ray, wave, RayWrites)   the ray's writes to the units' FIFOs
// Checked when compiling (is_gpp_clock_v), not a base class: the recipe's steps call their
// clock directly, with no virtual call on the path of every ray.
#pragma once

#include "timing/gpp_plan.h"

#include <cstdint>
#include <type_traits>
#include <utility>

namespace oprt::timing {

// What the GPP spends its cycles on (the waveform and the timeline name them).
enum class GppPhase { refit, generate, route, shade };

// A wave's writes: one to every FIFO (broadcast), one to the wave's FIFOs with a unit mask
// after the ray's bytes (masked), or one per unit of the wave (per_unit), each `bytes` long.
struct RayWrites {
  enum class Kind { broadcast, masked, per_unit } kind = Kind::broadcast;
  std::uint32_t transfers = 1;
  std::uint64_t bytes = 0;
  std::uint64_t ray_bytes = 0;  // of which the ray (the rest: the mask)
};

namespace clock_members {
// Each member as the recipe calls it (ill-formed where the clock lacks it).
template <typename C>
using compute = decltype(std::declval<C&>().compute(GppPhase::generate, std::uint64_t{}));
template <typename C>
using load = decltype(std::declval<C&>().load(std::declval<const MemoryLoad&>()));
template <typename C>
using write_config = decltype(std::declval<C&>().write_config(std::uint32_t{}, std::uint64_t{}));
template <typename C>
using generated = decltype(std::declval<C&>().generated(std::uint32_t{}));
template <typename C>
using routed_nowhere = decltype(std::declval<C&>().routed_nowhere(std::uint32_t{}));
template <typename C>
using write_rays = decltype(std::declval<C&>().write_rays(std::uint32_t{}, std::declval<const GppWave&>(),
                                                          std::declval<const RayWrites&>()));

template <typename C, template <typename> class Member, typename = void>
struct has : std::false_type {};
template <typename C, template <typename> class Member>
struct has<C, Member, std::void_t<Member<C>>> : std::true_type {};
}  // namespace clock_members

template <typename C>
struct is_gpp_clock
    : std::conjunction<clock_members::has<C, clock_members::compute>, clock_members::has<C, clock_members::load>,
                       clock_members::has<C, clock_members::write_config>, clock_members::has<C, clock_members::generated>,
                       clock_members::has<C, clock_members::routed_nowhere>,
                       clock_members::has<C, clock_members::write_rays>> {};
template <typename C>
inline constexpr bool is_gpp_clock_v = is_gpp_clock<C>::value;

}  // namespace oprt::timing
