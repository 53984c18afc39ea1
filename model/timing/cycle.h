// Time in the plain-C++ timing models: cycles of the units' clock. The SystemC modules
// convert simulation time to and from it; the analytic level restarts it at 0 every frame.
#pragma once

#include <cstdint>

namespace oprt::timing {

using Cycle = std::int64_t;

}  // namespace oprt::timing
