// Sampled frames expanded to the full frame (sample_estimate.h): what scales with the rays
// is multiplied by the expansion, what a frame does once (its start: the registers written,
// the geometry loaded, the refit) is kept.
#pragma once

#include "balance/policy_driver.h"
#include "stats.h"

namespace oprt {

// A count times e, rounded.
std::uint64_t expand_count(std::uint64_t v, double e);

// The frame's figures as the full frame would count them: every count of rays, work, bytes,
// FIFO traffic, cache, pipeline and router expanded by e; the start and the loads kept; the
// makespan and frame time the estimate's; an unbounded FIFO's peak as the full frame's would
// be (expand_unit); idle cycles recomputed. Its energy is left for the caller (the cost model on it).
FrameStats expand_frame(const FrameStats& fs, double e, std::uint64_t makespan, double frame_time_s, bool unbounded_fifos);

}  // namespace oprt
