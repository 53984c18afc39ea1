#include "timing/pipeline_timing.h"

#include <algorithm>
#include <stdexcept>

namespace oprt::timing {

const char* to_string(PipeStage s) {
  switch (s) {
    case PipeStage::node: return "node";
    case PipeStage::sphere: return "sphere";
    case PipeStage::transform: return "transform";
    case PipeStage::box: return "box";
    case PipeStage::triangle: return "triangle";
  }
  return "?";
}

FpUnits stage_units(const Arch& a, PipeStage s, const OpGraph& g) {
  const IuConfig::Unit* units[kPipeStages] = {&a.iu.node, &a.iu.sphere, &a.iu.transform, &a.iu.box, &a.iu.triangle};
  const IuConfig::Unit& u = *units[static_cast<int>(s)];
  FpUnits full = full_units(g, a.iu.add_latency, a.iu.multiply_latency);
  if (u.adders) full.adders = u.adders;
  if (u.multipliers) full.multipliers = u.multipliers;
  return full;
}

PipelineSchedules pipeline_schedules(const Arch& a) {
  const bool wt = a.kernel == Kernel::watertight;
  const bool bvh = a.accel == "bvh";
  const OpGraph* graphs[kPipeStages] = {
      &top_node_graph(), &sphere_stable_graph(),
      bvh ? &transform_box_setup_graph(a.kernel) : wt ? &transform_watertight_graph() : &transform_graph(),
      &box_graph(), wt ? &watertight_graph() : &moller_graph()};
  PipelineSchedules p;
  p.used[0] = a.top_tree();
  p.used[1] = p.used[2] = p.used[4] = true;
  p.used[3] = bvh;
  for (int s = 0; s < kPipeStages; ++s)
    if (p.used[s]) p.stage[s] = modulo_schedule(*graphs[s], stage_units(a, static_cast<PipeStage>(s), *graphs[s]));
  return p;
}

PipelineConfig pipeline_config(const Arch& a) {
  const PipelineSchedules p = pipeline_schedules(a);
  PipelineConfig c;
  for (int s = 0; s < kPipeStages; ++s) {
    if (!p.used[s]) continue;
    c.stage[s].used = true;
    c.stage[s].ii = p.stage[s].ii;
    c.stage[s].latency = p.stage[s].length();
    c.stage[s].units = stage_units(a, static_cast<PipeStage>(s), *p.stage[s].graph);
  }
  c.rays_in_flight = a.iu.rays_in_flight;
  c.stack_depth = a.iu.stack_depth;
  c.stack_overflow_cycles = a.iu.stack_overflow_cycles;
  return c;
}

// ------------------------------------------------------------------------------ one job

// A visit's bursts as the pipeline consumes them: each item's operation (a box test, or a
// triangle test) issued once its data is there and the operation it depends on has its
// result; a leaf's triangles independent of each other, in order.
class PipelinedUnitTiming::Job final : public BurstConsumer {
 public:
  Job(PipelinedUnitTiming& p, std::uint32_t ray, Cycle ready) : p_(p), ray_(ray), dep_(ready) {}
  Cycle consume(const VisitStream& v, std::size_t b, std::size_t, const Cycle* arrive) override {
    const VisitStream::Burst& burst = v.bursts[b];
    const PipeStage s = burst.node ? PipeStage::box : PipeStage::triangle;
    const Cycle ii = p_.c_.stage[static_cast<int>(s)].ii;
    Cycle last = dep_, next = dep_;
    for (std::uint32_t j = 0; j < burst.items; ++j) {
      if (arrive[j] > next) {  // the ray waits for its data
        p_.stats_.memory_wait += static_cast<std::uint64_t>(arrive[j] - next);
        if (p_.trace_) p_.trace_->memory(next, arrive[j]);
        next = arrive[j];
      }
      Cycle start = 0;
      last = std::max(last, p_.run(s, next, ray_, &start));
      next = start + ii;
    }
    dep_ = last;
    if (b + 1 < v.bursts.size() && b + 1 < v.stack_ops.size())
      dep_ += p_.c_.stack_overflow_cycles * v.stack_ops[b + 1];  // a spill or fill before the next node
    return dep_;
  }
  Cycle end() const { return dep_; }

 private:
  PipelinedUnitTiming& p_;
  const std::uint32_t ray_;
  Cycle dep_;
};

// ------------------------------------------------------------------------------ timing

PipelinedUnitTiming::PipelinedUnitTiming(const PipelineConfig& c, PipelineTrace* trace) : c_(c), trace_(trace) {
  for (const StageTiming& s : c_.stage)
    if (s.used && (s.ii < 1 || s.latency < 1)) throw std::invalid_argument("pipeline: II and latency must be >= 1");
  if (c_.rays_in_flight < 1) throw std::invalid_argument("pipeline: rays_in_flight must be >= 1");
}

void PipelinedUnitTiming::reset_stats() { stats_ = PipelineStats{}; }

Cycle PipelinedUnitTiming::ready() const {
  const Cycle g = next_take_;
  const auto slots = static_cast<std::uint64_t>(c_.rays_in_flight);
  if (unretired_ >= slots) return kNever;
  auto later = leaving_.upper_bound(g);
  const auto held = unretired_ + static_cast<std::uint64_t>(std::distance(later, leaving_.end()));
  if (held < slots) return g;
  std::advance(later, static_cast<std::ptrdiff_t>(held - slots));  // the answer whose leaving frees a slot
  return *later;
}

Cycle PipelinedUnitTiming::run(PipeStage s, Cycle ready, std::uint32_t ray, Cycle* start_out) {
  const int i = static_cast<int>(s);
  const StageTiming& st = c_.stage[i];
  if (!st.used) throw std::logic_error(std::string("pipeline: an operation for the absent ") + to_string(s) + " unit");
  Cycle start = 0;
  slots_[i].reserve(ready, st.ii, &start);
  ++stats_.stage[i].ops;
  stats_.stage[i].busy += static_cast<std::uint64_t>(st.ii);
  if (trace_) {
    if (start > ready) trace_->waiting(s, ready, start);
    trace_->issue(s, start, start + st.ii, ray);
  }
  if (start_out) *start_out = start;
  return start + st.latency;
}

Cycle PipelinedUnitTiming::job(const PipelineRay& ray, std::uint32_t i, Cycle ready, VisitReader& memory) {
  ++stats_.jobs;
  Cycle issued = 0;
  const Cycle transformed = run(PipeStage::transform, ready, ray.id, &issued);
  const VisitStream& s = ray.streams[i];
  stats_.stack_pushes += s.pushes;
  stats_.stack_spills += s.spills;
  stats_.stack_fills += s.fills;
  if (s.bursts.empty()) return transformed;
  Job unit(*this, ray.id, transformed);
  // The first burst is requested when the transform issues: the transform hides latency.
  memory.read(s, issued, unit);
  return std::max(unit.end(), transformed);
}

PipelinedUnitTiming::Taken PipelinedUnitTiming::take(Cycle t, Cycle arrived, const PipelineRay& ray,
                                                     VisitReader& memory) {
  leaving_.erase(leaving_.begin(), leaving_.upper_bound(t));
  const auto held = unretired_ + leaving_.size();
  if (held >= static_cast<std::size_t>(c_.rays_in_flight) || t < next_take_)
    throw std::logic_error("pipeline: a ray taken before the unit was ready");
  stats_.peak_in_flight = std::max(stats_.peak_in_flight, static_cast<std::uint32_t>(held + 1));
  // It could have been taken from `from` but for a free ray slot.
  const Cycle from = std::max(next_take_, arrived);
  if (t > from) stats_.slot_wait += static_cast<std::uint64_t>(t - from);
  next_take_ = t + 1;
  for (Calendar<Cycle>& c : slots_) c.forget_before(t);  // no operation of this ray or a later one is earlier
  if (trace_) trace_->in_flight(t, +1);

  Cycle done = t;
  if (!ray.tree) {
    // The flat list: every test independent; each entered sphere's job when its test's
    // result is there and the ray's job before is done.
    std::uint32_t k = 0;
    Cycle jobs_done = t;
    for (std::uint32_t e = 0; e < ray.sphere_tests; ++e) {
      const Cycle result = run(PipeStage::sphere, t, ray.id);
      done = std::max(done, result);
      if (k < ray.n_visits && ray.visits[k].entry == e) jobs_done = job(ray, k++, std::max(result, jobs_done), memory);
    }
    if (k != ray.n_visits) throw std::logic_error("pipeline: an entered sphere beyond the ray's sphere tests");
    done = std::max(done, jobs_done);
  } else {
    // The tree: one chain of dependent tests and jobs.
    auto tests = [&](PipeStage s, std::uint32_t n) {
      for (std::uint32_t j = 0; j < n; ++j) done = run(s, done, ray.id);
    };
    for (std::uint32_t k = 0; k < ray.n_visits; ++k) {
      tests(PipeStage::node, ray.visits[k].nodes_before);
      tests(PipeStage::sphere, ray.visits[k].spheres_before);
      done = job(ray, k, done, memory);
    }
    tests(PipeStage::node, ray.trailing_nodes);
    tests(PipeStage::sphere, ray.trailing_spheres);
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

// ------------------------------------------------------------------------------ the stack

template <typename T>
void count_stack_overflows(const SceneGeometry<T>& g, const GeometryAddresses<T>& at, int depth, VisitStream& v) {
  v.stack_ops.assign(v.bursts.size(), 0);
  v.pushes = v.spills = v.fills = 0;
  std::uint32_t in_registers = 0, spilled = 0;
  std::int64_t prev = -1;
  for (std::size_t b = 0; b < v.bursts.size(); ++b) {
    if (!v.bursts[b].node) continue;
    const auto id = static_cast<std::int64_t>((v.bursts[b].address - at.node_base) / at.node_bytes);
    if (prev >= 0) {
      const BvhNode<T>& p = g.nodes[static_cast<std::size_t>(prev)];
      if (!p.leaf() && (id == prev + 1 || id == static_cast<std::int64_t>(p.offset))) {  // descended: pushed the sibling
        ++v.pushes;
        if (in_registers == static_cast<std::uint32_t>(depth)) {  // the bottom entry goes to memory
          ++v.spills;
          ++spilled;
          ++v.stack_ops[b];
        } else {
          ++in_registers;
        }
      } else if (in_registers > 0) {  // popped
        --in_registers;
      } else if (spilled > 0) {  // popped an entry that was spilled: filled back first
        --spilled;
        ++v.fills;
        ++v.stack_ops[b];
      }
    }
    prev = id;
  }
}

template void count_stack_overflows(const SceneGeometry<float>&, const GeometryAddresses<float>&, int, VisitStream&);
template void count_stack_overflows(const SceneGeometry<double>&, const GeometryAddresses<double>&, int,
                                    VisitStream&);

}  // namespace oprt::timing
