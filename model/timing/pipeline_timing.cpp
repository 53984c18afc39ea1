#include "timing/pipeline_timing.h"

#include <algorithm>
#include <stdexcept>

namespace oprt::hw {

const char* to_string(PipeStage s) {
  switch (s) {
    case PipeStage::sphere: return "sphere";
    case PipeStage::transform: return "transform";
    case PipeStage::triangle: return "triangle";
  }
  return "?";
}

FpUnits stage_units(const Arch& a, PipeStage s, const OpGraph& g) {
  const IuConfig::Unit& u = s == PipeStage::sphere ? a.iu.sphere : s == PipeStage::transform ? a.iu.transform : a.iu.triangle;
  FpUnits full = full_units(g, a.iu.add_latency, a.iu.multiply_latency);
  if (u.adders) full.adders = u.adders;
  if (u.multipliers) full.multipliers = u.multipliers;
  return full;
}

PipelineSchedules pipeline_schedules(const Arch& a) {
  const bool wt = a.kernel == Kernel::watertight;
  const OpGraph* graphs[kPipeStages] = {&sphere_stable_graph(), wt ? &transform_watertight_graph() : &transform_graph(),
                                        wt ? &watertight_graph() : &moller_graph()};
  PipelineSchedules p;
  for (int s = 0; s < kPipeStages; ++s)
    p.stage[s] = modulo_schedule(*graphs[s], stage_units(a, static_cast<PipeStage>(s), *graphs[s]));
  return p;
}

PipelineConfig pipeline_config(const Arch& a, std::uint32_t triangle_bytes) {
  const PipelineSchedules p = pipeline_schedules(a);
  PipelineConfig c;
  for (int s = 0; s < kPipeStages; ++s) {
    c.stage[s].ii = p.stage[s].ii;
    c.stage[s].latency = p.stage[s].length();
    c.stage[s].units = stage_units(a, static_cast<PipeStage>(s), *p.stage[s].graph);
  }
  c.queue_depth = a.iu.queue_depth;
  c.rays_in_flight = a.iu.rays_in_flight;
  c.memory_latency = a.memory.model == MemoryModel::latency;
  c.memory_latency_cycles = a.memory.latency_cycles;
  c.memory_bytes_per_cycle = a.memory.bytes_per_cycle;
  c.triangle_bytes = triangle_bytes;
  return c;
}

// ---------------------------------------------------------------------------- a stage's time

Cycle PipelinedUnitTiming::Stage::global(Cycle v) const {
  for (auto f = freezes.rbegin(); f != freezes.rend(); ++f)
    if (f->at <= v) return v + f->total;
  return v + base;
}

Cycle PipelinedUnitTiming::Stage::virtual_of(Cycle g) const {
  Cycle from = INT64_MIN, total = base;
  for (const Freeze& f : freezes) {  // virtual [from, f.at) maps to global with `total` added
    const Cycle v = std::max(from, g - total);
    if (v < f.at) return v;
    from = f.at;
    total = f.total;
  }
  return std::max(from, g - total);
}

void PipelinedUnitTiming::Stage::freeze(Cycle at, Cycle d) {
  const Cycle total = (freezes.empty() ? base : freezes.back().total) + d;
  if (!freezes.empty() && freezes.back().at > at) throw std::logic_error("pipeline: freezes out of order");
  if (!freezes.empty() && freezes.back().at == at) freezes.back().total = total;
  else freezes.push_back({at, total});
}

void PipelinedUnitTiming::Stage::forget_before(Cycle v) {
  while (!freezes.empty() && freezes.front().at < v) {
    base = freezes.front().total;
    freezes.pop_front();
  }
}

// ------------------------------------------------------------------------------------ queues

Cycle PipelinedUnitTiming::room(const Queue& q, Cycle g) const {
  if (c_.queue_depth == 0 || q.pops.size() < static_cast<std::size_t>(c_.queue_depth)) return g;
  return std::max(g, q.pops.front());
}

void PipelinedUnitTiming::push(Queue& q, int index, Cycle at, Cycle pop) {
  if (c_.queue_depth > 0) {
    q.pops.push_back(pop);
    if (q.pops.size() > static_cast<std::size_t>(c_.queue_depth)) q.pops.pop_front();
  }
  // Entries are pushed, and popped, in nondecreasing time: those still queued at `at` are
  // the ones popped after it.
  while (!q.pending.empty() && q.pending.front() <= at) q.pending.pop_front();
  stats_.peak_queue[index] = std::max(stats_.peak_queue[index], static_cast<std::uint32_t>(q.pending.size() + 1));
  q.pending.push_back(pop);
  if (trace_) {
    trace_->queue(index, at, +1);
    trace_->queue(index, pop, -1);
  }
}

Cycle PipelinedUnitTiming::enter(Stage& s, PipeStage which, Cycle v, const Queue& q) {
  const Cycle g = s.global(v);
  const Cycle f = room(q, g);
  if (f == g) return g;
  s.freeze(v, f - g);
  s.recent.emplace_back(g, f);
  stats_.stage[static_cast<int>(which)].full += static_cast<std::uint64_t>(f - g);
  return f;
}

// The stage's waveform for an issue window [v0, v_end) (virtual): busy while it issues,
// full while frozen, waiting after. Freezes after the window were reported as "full, then
// waiting"; a later window that covers their end reports "busy" there instead (the last
// report at a time holds).
void PipelinedUnitTiming::trace_window(Stage& s, PipeStage which, Cycle v0, Cycle v_end) {
  const Cycle g0 = s.global(v0), g_end = s.global(v_end - 1) + 1;
  while (!s.recent.empty() && s.recent.front().second <= g0) s.recent.pop_front();
  if (!trace_) return;
  trace_->stage(which, g0, StageState::busy);
  trace_->stage(which, g_end, StageState::waiting);
  for (const auto& [a, b] : s.recent) {
    trace_->stage(which, a, StageState::full);
    trace_->stage(which, b, b < g_end ? StageState::busy : StageState::waiting);
  }
}

// ------------------------------------------------------------------------------------ timing

PipelinedUnitTiming::PipelinedUnitTiming(const PipelineConfig& c, PipelineTrace* trace) : c_(c), trace_(trace) {
  for (const StageTiming& s : c_.stage)
    if (s.ii < 1 || s.latency < 1) throw std::invalid_argument("pipeline: II and latency must be >= 1");
  if (c_.rays_in_flight < 1) throw std::invalid_argument("pipeline: rays_in_flight must be >= 1");
}

void PipelinedUnitTiming::reset_stats() { stats_ = PipelineStats{}; }

// A later take() reports the sphere unit "full" from its next issue slot at the earliest, and
// the next window of a stage reports its recent freezes again: nothing before those.
Cycle PipelinedUnitTiming::trace_floor() const {
  Cycle f = sphere_.global(sphere_.next_v);
  for (const Stage* s : {&sphere_, &transform_})
    for (const auto& [a, b] : s->recent) f = std::min(f, a);
  return f;
}

Cycle PipelinedUnitTiming::ready() const {
  const Cycle g = sphere_.global(sphere_.next_v);
  const auto slots = static_cast<std::uint64_t>(c_.rays_in_flight);
  if (unretired_ >= slots) return kNever;
  auto later = leaving_.upper_bound(g);
  const auto held = unretired_ + static_cast<std::uint64_t>(std::distance(later, leaving_.end()));
  if (held < slots) return g;
  std::advance(later, static_cast<std::ptrdiff_t>(held - slots));  // the answer whose leaving frees a slot
  return *later;
}

void PipelinedUnitTiming::job(Cycle entered, std::uint32_t triangles, Cycle& done) {
  const StageTiming& tt = c_.stage[1];
  const StageTiming& tr = c_.stage[2];
  // Transform unit: the next issue slot at or after the job's arrival.
  const Cycle v = std::max(transform_.next_v, transform_.virtual_of(entered));
  const Cycle issued = transform_.global(v);
  push(q_[0], 0, entered, issued);
  transform_.next_v = v + tt.ii;
  stats_.stage[1].busy += static_cast<std::uint64_t>(tt.ii);
  const Cycle ready = enter(transform_, PipeStage::transform, v + tt.latency, q_[1]);
  trace_window(transform_, PipeStage::transform, v, v + tt.ii);
  transform_.forget_before(v);

  // Triangle unit: one job at a time, one triangle every II.
  const Cycle start = std::max(ready, triangle_free_);
  push(q_[1], 1, ready, start);
  if (triangles == 0) {
    done = std::max(done, start);
    return;
  }
  const Cycle n = triangles;
  const Cycle unstalled = start + (n - 1) * tr.ii;
  Cycle first = start, last = unstalled;
  if (c_.memory_latency) {
    // One burst, requested when the transform started, streamed after the previous one.
    const Cycle b = std::max(issued + c_.memory_latency_cycles, memory_free_);
    const Cycle bytes = c_.triangle_bytes, rate = c_.memory_bytes_per_cycle;
    const Cycle arrive_first = b + (bytes + rate - 1) / rate;
    const Cycle arrive_last = b + (n * bytes + rate - 1) / rate;
    memory_free_ = arrive_last;
    // Triangle j issues at max(start + j II, max over i <= j of arrive_i + (j - i) II); the
    // arrivals are spaced floor or ceil(bytes / rate) apart, so the maximum over i is at
    // the last arrival when the memory is the slower (floor >= II), else at the first.
    first = std::max(start, arrive_first);
    last = std::max(first + (n - 1) * tr.ii, bytes / rate >= tr.ii ? arrive_last : arrive_first + (n - 1) * tr.ii);
    stats_.stage[2].memory += static_cast<std::uint64_t>(last - unstalled);
  }
  triangle_free_ = last + tr.ii;
  stats_.stage[2].busy += static_cast<std::uint64_t>(n * tr.ii);
  stats_.triangles += static_cast<std::uint64_t>(n);
  done = std::max(done, last + tr.latency);
  if (trace_) {
    if (first > start) trace_->stage(PipeStage::triangle, start, StageState::memory);
    trace_->stage(PipeStage::triangle, first, StageState::busy);
    trace_->stage(PipeStage::triangle, triangle_free_, StageState::waiting);
  }
}

PipelinedUnitTiming::Taken PipelinedUnitTiming::take(Cycle t, Cycle arrived, std::uint32_t sphere_tests,
                                                     const VisitWork* visits, std::uint32_t n_visits) {
  const StageTiming& ts = c_.stage[0];
  const Cycle free = sphere_.global(sphere_.next_v);
  leaving_.erase(leaving_.begin(), leaving_.upper_bound(t));
  const auto held = unretired_ + leaving_.size();
  if (held >= static_cast<std::size_t>(c_.rays_in_flight) || t < free)
    throw std::logic_error("pipeline: a ray taken before the unit was ready");
  stats_.peak_in_flight = std::max(stats_.peak_in_flight, static_cast<std::uint32_t>(held + 1));
  if (trace_) trace_->in_flight(t, +1);
  // The sphere unit had a ray waiting and a free issue slot from `from`, but no free ray
  // slot until t: a stall of the sphere unit, except where it was frozen anyway.
  const Cycle from = std::max(free, arrived);
  if (t > from) {
    Cycle wait = t - from;
    for (const auto& [a, b] : sphere_.recent) wait -= std::max<Cycle>(0, std::min(b, t) - std::max(a, from));
    stats_.stage[0].full += static_cast<std::uint64_t>(wait);
    if (trace_) {
      trace_->stage(PipeStage::sphere, from, StageState::full);
      for (const auto& [a, b] : sphere_.recent)
        if (b > from && b <= t) trace_->stage(PipeStage::sphere, b, StageState::full);
    }
  }

  const Cycle v0 = std::max(sphere_.next_v, sphere_.virtual_of(t));
  sphere_.forget_before(sphere_.next_v);
  Cycle done = sphere_.global(v0);
  for (std::uint32_t i = 0; i < n_visits; ++i) {
    const VisitWork& w = visits[i];
    const Cycle entered = enter(sphere_, PipeStage::sphere, v0 + static_cast<Cycle>(w.entry) * ts.ii + ts.latency, q_[0]);
    ++stats_.jobs;
    job(entered, w.tri_tests, done);
  }
  if (sphere_tests) {
    const Cycle v_end = v0 + static_cast<Cycle>(sphere_tests) * ts.ii;
    sphere_.next_v = v_end;
    stats_.stage[0].busy += static_cast<std::uint64_t>(v_end - v0);
    done = std::max(done, sphere_.global(v_end - ts.ii + ts.latency));  // the last test's result
    trace_window(sphere_, PipeStage::sphere, v0, v_end);
  }
  spans_.push_back({t, kNever});
  ++unretired_;
  return {first_span_ + spans_.size() - 1, done};
}

void PipelinedUnitTiming::retire(Handle h, Cycle done, Cycle t) {
  if (h < first_span_ || h - first_span_ >= spans_.size() || unretired_ == 0 || t < done)
    throw std::logic_error("pipeline: retiring a ray that is not in flight");
  --unretired_;
  leaving_.insert(t);
  stats_.answer_wait += static_cast<std::uint64_t>(t - done);
  spans_[h - first_span_].end = t;
  if (trace_) trace_->in_flight(t, -1);
  // Spans in take order: the union of those whose ends are known.
  while (!spans_.empty() && spans_.front().end != kNever) {
    const Span s = spans_.front();
    const Cycle from = std::max(s.start, covered_until_);
    if (s.end > from) stats_.occupied += static_cast<std::uint64_t>(s.end - from);
    covered_until_ = std::max(covered_until_, s.end);
    spans_.pop_front();
    ++first_span_;
  }
}

}  // namespace oprt::hw
