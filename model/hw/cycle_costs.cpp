#include "hw/cycle_costs.h"

#include "hw/cycle_schedule.h"

namespace oprt {

CycleCosts scheduled_costs() {
  CycleCosts c;
  c.sphere = static_cast<std::uint32_t>(list_schedule(sphere_stable_graph()).length());
  c.transform = static_cast<std::uint32_t>(list_schedule(transform_graph()).length());
  const Schedule m = list_schedule(moller_graph());
  for (int k = 0; k < kTriStages; ++k) c.tri_stage[k] = static_cast<std::uint32_t>(m.exit_cycle[k]);
  c.box_setup = static_cast<std::uint32_t>(list_schedule(box_setup_graph()).length());
  c.box = static_cast<std::uint32_t>(list_schedule(box_graph()).length());
  return c;
}

}  // namespace oprt
