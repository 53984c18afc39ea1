#include "arch/cycle_costs.h"

#include "arch/cycle_schedule.h"

namespace oprt {

namespace {
KernelCosts kernel_costs(const OpGraph& transform, const OpGraph& triangle) {
  KernelCosts c;
  c.transform = static_cast<std::uint32_t>(list_schedule(transform).length());
  const Schedule s = list_schedule(triangle);
  for (int k = 0; k < kTriStages; ++k) c.tri_stage[k] = static_cast<std::uint32_t>(s.exit_cycle.at(k));
  return c;
}
}  // namespace

CycleCosts scheduled_costs() {
  CycleCosts c;
  c.sphere = static_cast<std::uint32_t>(list_schedule(sphere_stable_graph()).length());
  c.moller = kernel_costs(transform_graph(), moller_graph());
  c.watertight = kernel_costs(transform_watertight_graph(), watertight_graph());
  c.box_setup = static_cast<std::uint32_t>(list_schedule(box_setup_graph()).length());
  c.box = static_cast<std::uint32_t>(list_schedule(box_graph()).length());
  c.node = static_cast<std::uint32_t>(list_schedule(top_node_graph()).length());
  return c;
}

}  // namespace oprt
