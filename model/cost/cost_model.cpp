#include "cost/cost_model.h"

#include "geom/bvh.h"
#include "base/error.h"
#include "geom/triangle_soa.h"
#include "ref/bytes.h"

#include <cmath>
#include <sstream>
#include <stdexcept>

namespace oprt {

FpOps ops_until_exit(const Schedule& s, int stage) {
  if (!s.graph || stage < 0 || stage >= static_cast<int>(s.exit_cycle.size()))
    throw std::out_of_range("ops_until_exit: no such stage");
  const int until = s.exit_cycle[stage];
  FpOps n;
  for (std::size_t i = 0; i < s.graph->ops.size(); ++i) {
    if (s.cycle[i] > until) continue;
    const Op& op = s.graph->ops[i];
    if (op.fu == Fu::multiplier) ++n.multiply;
    else if (op.compare) ++n.compare;
    else ++n.add;
  }
  return n;
}

OpCounts op_counts(Kernel k, const std::function<Schedule(const OpGraph&)>& schedule) {
  const auto whole = [&](const OpGraph& g) {
    const Schedule s = schedule(g);
    return ops_until_exit(s, static_cast<int>(s.exit_cycle.size()) - 1);
  };
  const bool wt = k == Kernel::watertight;
  OpCounts c;
  c.sphere = whole(sphere_stable_graph());
  c.transform = whole(wt ? transform_watertight_graph() : transform_graph());
  const Schedule tri = schedule(wt ? watertight_graph() : moller_graph());
  if (tri.exit_cycle.size() != kTriStages) throw std::logic_error("op_counts: a triangle graph needs 4 exit stages");
  for (int st = 0; st < kTriStages; ++st) c.triangle[st] = ops_until_exit(tri, st);
  c.box_setup = whole(box_setup_graph());
  c.box = whole(box_graph());
  c.node = whole(top_node_graph());
  return c;
}

WorkOps work_ops(const OpCounts& c, const WorkCounts& w) {
  WorkOps n;
  n.core = c.sphere.times(w.sphere_tests);
  n.core += c.transform.times(w.transforms);
  for (int st = 0; st < kTriStages; ++st) n.core += c.triangle[st].times(w.tri_stage[st]);
  n.box = c.box_setup.times(w.box_setups);
  n.box += c.box.times(w.box_tests);
  n.node = c.node.times(w.node_tests);
  return n;
}

FpOps ops_of(const OpCounts& c, const WorkCounts& w) {
  const WorkOps n = work_ops(c, w);
  FpOps all = n.core;
  all += n.box;
  all += n.node;
  return all;
}

std::optional<double> Cost::of(const std::string& name) const {
  for (const auto& c : components)
    if (c.name == name) return c.value;
  throw std::out_of_range("Cost: no component " + name);
}

nlohmann::json Cost::to_json() const {
  nlohmann::json j = {{"total", total}};
  for (const auto& c : components) j[c.name] = c.value ? nlohmann::json(*c.value) : nlohmann::json(nullptr);
  return j;
}

namespace {

std::string bytes_text(double b) {
  std::ostringstream s;
  if (b >= 1024.0 * 1024 && std::fmod(b, 1024.0 * 1024) == 0) s << b / (1024.0 * 1024) << " MiB";
  else if (b >= 1024 && std::fmod(b, 1024) == 0) s << b / 1024 << " KiB";
  else s << b << " bytes";
  return s.str();
}

// Accumulates components; `scale` converts the table's unit to the report's (pJ -> J).
class Builder {
 public:
  explicit Builder(double scale = 1) : scale_(scale) {}

  // quantity x price; a missing price is fine while the quantity is 0.
  void charge(const std::string& name, double quantity, std::optional<double> price, const std::string& missing) {
    if (quantity == 0) return put(name, 0.0);
    if (!price) {
      note(name + ": not charged: the table has no " + missing);
      return put(name, std::nullopt);
    }
    put(name, quantity * *price);
  }
  void put(const std::string& name, std::optional<double> value) {
    if (value) value = *value * scale_;
    cost_.components.push_back({name, value});
    if (value) cost_.total += *value;
  }
  void note(const std::string& text) { cost_.notes.push_back(text); }
  Cost take() { return std::move(cost_); }

 private:
  double scale_;
  Cost cost_;
};

// Sums a size curve over the units' capacities (0 = the unit has none), noting the ones
// outside the table.
class SramSum {
 public:
  SramSum(const SizeCurve& curve, std::string what) : curve_(curve), what_(std::move(what)) {}
  double at(double bytes) {
    const SizeCurve::Lookup l = curve_.at(bytes);
    if (l.range == SizeCurve::Range::below) ++below_;
    if (l.range == SizeCurve::Range::above) ++above_;
    return l.value;
  }
  void notes(Builder& b, const std::string& component) const {
    if (below_)
      b.note(component + ": " + std::to_string(below_) + " " + what_ + " smaller than the table's smallest SRAM (" +
             bytes_text(curve_.points().front().bytes) + "), charged at its value (an over-estimate)");
    if (above_)
      b.note(component + ": " + std::to_string(above_) + " " + what_ + " larger than the table's largest SRAM (" +
             bytes_text(curve_.points().back().bytes) + "), extrapolated from its two largest points");
  }

 private:
  const SizeCurve& curve_;
  std::string what_;
  int below_ = 0, above_ = 0;
};

// Sum over the units of price(capacity) x quantity, for the units with a quantity; a curve
// the table lacks makes the component null.
template <typename Capacity, typename Quantity>
void charge_by_size(Builder& b, const std::string& name, const SizeCurve& curve, const std::string& missing,
                    const std::string& what, std::size_t n, Capacity capacity, Quantity quantity) {
  double total_quantity = 0;
  for (std::size_t u = 0; u < n; ++u) total_quantity += quantity(u);
  if (total_quantity == 0) return b.put(name, 0.0);
  if (curve.empty()) {
    b.note(name + ": not charged: the table has no " + missing);
    return b.put(name, std::nullopt);
  }
  SramSum sum(curve, what);
  double value = 0;
  for (std::size_t u = 0; u < n; ++u) {
    const double q = quantity(u);
    if (q == 0) continue;
    const double cap = capacity(u);
    if (!(cap > 0)) throw std::invalid_argument(name + ": unit " + std::to_string(u) + " has activity but no capacity");
    value += q * sum.at(cap);
  }
  sum.notes(b, name);
  b.put(name, value);
}

std::optional<double> per_byte(const std::optional<double>& price, const std::optional<double>& bytes) {
  if (!price || !bytes) return std::nullopt;
  return *price / *bytes;
}

// Ray FIFOs: one smaller than the table's smallest SRAM is built from registers, and is
// charged at the register file's price per byte (`rf_price` x `rf_quantity`, bytes) when
// the table has one; the others as SRAM by capacity (charge_by_size).
template <typename Capacity, typename Quantity, typename RfQuantity>
void charge_fifos(Builder& b, const std::string& name, const SizeCurve& curve, std::optional<double> rf_price,
                  const std::string& missing, std::size_t n, Capacity capacity, Quantity quantity,
                  RfQuantity rf_quantity) {
  const auto small = [&](std::size_t u) {
    return rf_price && !curve.empty() && capacity(u) > 0 && capacity(u) < curve.points().front().bytes;
  };
  double registers = 0;
  int count = 0;
  for (std::size_t u = 0; u < n; ++u)
    if (small(u) && quantity(u) > 0) registers += rf_quantity(u) * *rf_price, ++count;
  Builder sram;
  charge_by_size(sram, name, curve, missing, "ray FIFOs", n, capacity,
                 [&](std::size_t u) { return small(u) ? 0.0 : quantity(u); });
  Cost c = sram.take();
  for (const std::string& note : c.notes) b.note(note);
  if (count)
    b.note(name + ": " + std::to_string(count) + " ray FIFOs smaller than the table's smallest SRAM (" +
           bytes_text(curve.points().front().bytes) + ") are registers, charged at the register file's price per byte");
  const std::optional<double> v = c.components.front().value;
  b.put(name, v ? std::optional<double>(*v + registers) : std::nullopt);
}

// Area of a unit of `adders` adders and `multipliers` multipliers; null if the table lacks either.
std::optional<double> fp_area(const Tech& t, int adders, int multipliers) {
  if ((adders && !t.fp_add.area_mm2) || (multipliers && !t.fp_multiply.area_mm2)) return std::nullopt;
  return adders * t.fp_add.area_mm2.value_or(0) + multipliers * t.fp_multiply.area_mm2.value_or(0);
}

// Energy of a set of operations (a comparison at `compare`); null if the table lacks a price needed.
std::optional<double> op_energy(const Tech& t, const FpOps& o, const std::optional<double>& compare) {
  const std::pair<std::uint64_t, std::optional<double>> parts[] = {
      {o.add, t.fp_add.energy_pj}, {o.multiply, t.fp_multiply.energy_pj}, {o.compare, compare}, {o.inverse, t.fp_inverse.energy_pj}};
  double e = 0;
  for (const auto& [n, price] : parts) {
    if (!n) continue;
    if (!price) return std::nullopt;
    e += static_cast<double>(n) * *price;
  }
  return e;
}

void precision_note(Builder& b, const Design& d) {
  if (d.double_precision) b.note("the table's FP units are 32-bit: double precision is charged as single");
}

}  // namespace

namespace {
// Every figure of a table's cost, checked where it is formed: a product of a table's value
// and a run's counts that overflows, or a size curve extrapolated to infinity, names the table
// instead of reaching stats.json as null or stats.csv as inf.
Cost finite(Cost c, const Tech& t, const char* what) {
  for (const auto& comp : c.components)
    if (comp.value && !std::isfinite(*comp.value))
      throw InputError(t.file, comp.name,
                       std::string("the run's ") + what + " is not a finite number with this table's values: lower them");
  if (!std::isfinite(c.total))
    throw InputError(t.file, "", std::string("the run's total ") + what + " is not a finite number with this table's values");
  return c;
}
}  // namespace

Cost area_mm2(const Tech& t, const Design& d) {
  Builder b;
  const auto n = static_cast<double>(d.units.size());
  b.charge("fp_adders", n * d.iu.adders, t.fp_add.area_mm2, "fp_add area");
  b.charge("fp_multipliers", n * d.iu.multipliers, t.fp_multiply.area_mm2, "fp_multiply area");
  b.charge("fp_comparators", n * d.iu.comparators, t.fp_compare.area_mm2, "fp_compare area");
  b.charge("fp_inverters", n * d.iu.inverters, t.fp_inverse.area_mm2, "fp_inverse area");
  b.charge("register_files", n * d.iu.register_files, t.register_file.area_mm2, "register_file area");
  b.charge("box_units", n, fp_area(t, d.iu.box_adders, d.iu.box_multipliers), "fp_add and fp_multiply area");
  b.charge("router", 1.0,
           [&]() -> std::optional<double> {
             const std::optional<double> fp = fp_area(t, d.router_adders, d.router_multipliers);
             const std::optional<double> rf = per_byte(t.register_file.area_mm2, t.register_file.bytes);
             if (!fp || (d.router_register_bytes && !rf)) return std::nullopt;
             return *fp + static_cast<double>(d.router_register_bytes) * rf.value_or(0);
           }(),
           "fp_add, fp_multiply or register_file area");
  b.charge("node_units", n, fp_area(t, d.iu.node_adders, d.iu.node_multipliers), "fp_add and fp_multiply area");
  double config = 0;
  for (const UnitSize& u : d.units) config += static_cast<double>(u.config_bytes);
  b.charge("configuration_registers", config, per_byte(t.register_file.area_mm2, t.register_file.bytes),
           "register_file area (configuration registers are charged at its area per byte)");
  double buffers = 0;
  for (const UnitSize& u : d.units) buffers += static_cast<double>(u.buffer_bytes);
  b.charge("pipeline_buffers", buffers, per_byte(t.register_file.area_mm2, t.register_file.bytes),
           "register_file area (a pipelined IU's buffers are charged at its area per byte)");
  double stacks = 0, miss = 0;
  for (const UnitSize& u : d.units) stacks += static_cast<double>(u.stack_bytes), miss += static_cast<double>(u.miss_register_bytes);
  b.charge("traversal_stacks", stacks, per_byte(t.register_file.area_mm2, t.register_file.bytes),
             "register_file area (the traversal stacks are charged at its area per byte)");
  b.charge("miss_registers", miss, per_byte(t.register_file.area_mm2, t.register_file.bytes),
             "register_file area (a cache's miss registers are charged at its area per byte)");
  const std::size_t units = d.units.size();
  charge_by_size(
      b, "object_memories", t.sram.area_mm2, "sram area", "object memories", units,
      [&](std::size_t u) { return static_cast<double>(d.units[u].object_memory_bytes); },
      [&](std::size_t u) { return d.units[u].object_memory_bytes ? 1.0 : 0.0; });
  charge_fifos(b, "ray_fifos", t.sram.area_mm2, per_byte(t.register_file.area_mm2, t.register_file.bytes), "sram area",
               units, [&](std::size_t u) { return static_cast<double>(d.units[u].fifo_bytes); },
               [&](std::size_t u) { return d.units[u].fifo_bytes ? 1.0 : 0.0; },
               [&](std::size_t u) { return static_cast<double>(d.units[u].fifo_bytes); });
  precision_note(b, d);
  return finite(b.take(), t, "area");
}

Cost frame_energy_j(const Tech& t, const Design& d, const OpCounts& per_op, const FrameActivity& f) {
  if (f.units.size() != d.units.size()) throw std::invalid_argument("frame_energy_j: one activity per unit of the design");
  Builder b(1e-12);  // the table is in pJ
  FpOps ops, box, node;
  for (const UnitActivity& u : f.units) {
    const WorkOps w = work_ops(per_op, u.work);
    ops += w.core;
    box += w.box;
    node += w.node;
  }

  b.charge("fp_add", static_cast<double>(ops.add), t.fp_add.energy_pj, "fp_add energy");
  b.charge("fp_multiply", static_cast<double>(ops.multiply), t.fp_multiply.energy_pj, "fp_multiply energy");
  // A comparison is a subtraction whose sign is read: on the adder unless the IU has
  // comparators; a table without a comparator's energy charges the adder's.
  std::optional<double> compare = t.fp_add.energy_pj;
  if (d.iu.comparators > 0) {
    if (t.fp_compare.energy_pj) compare = t.fp_compare.energy_pj;
    else if (ops.compare) b.note("fp_compare: the table has no fp_compare energy: comparisons charged at the adder's");
  }
  b.charge("fp_compare", static_cast<double>(ops.compare), compare, "fp_add energy (comparisons run on the adder)");
  b.charge("fp_inverse", static_cast<double>(ops.inverse), t.fp_inverse.energy_pj, "fp_inverse energy");
  // The box set-ups and tests, and the node tests: the energy of their operations, whichever
  // units run them (their own in a pipelined IU, the adder and multiplier of a serial one).
  b.charge("box_tests", 1.0, op_energy(t, box, compare), "fp_add and fp_multiply energy");
  b.charge("node_tests", 1.0, op_energy(t, node, compare), "fp_add and fp_multiply energy");
  // The router: a box test per unit bound a ray is tested against, and the bound's read.
  std::optional<double> router = op_energy(t, per_op.box.times(f.router_tests), compare);
  if (router && f.router_tests) {
    if (t.register_file.energy_pj) *router += static_cast<double>(f.router_tests) * *t.register_file.energy_pj;
    else router.reset();
  }
  b.charge("router", 1.0, router, "fp_add, fp_multiply or register_file energy");
  b.charge("register_file", d.iu.register_accesses_per_op * static_cast<double>(ops.total() + box.total() + node.total()),
           t.register_file.energy_pj, "register_file energy");

  const std::size_t units = d.units.size();
  const auto sram_access = t.sram.access_bytes.value_or(1);
  charge_by_size(
      b, "object_memory_reads", t.sram.read_energy_pj, "sram read_energy", "object memories", units,
      [&](std::size_t u) { return static_cast<double>(d.units[u].object_memory_bytes); },
      [&](std::size_t u) { return static_cast<double>(f.units[u].memory_read_bytes) / sram_access; });
  charge_by_size(
      b, "object_memory_writes", t.sram.read_energy_pj, "sram read_energy", "object memories", units,
      [&](std::size_t u) { return static_cast<double>(d.units[u].object_memory_bytes); },
      [&](std::size_t u) { return static_cast<double>(f.units[u].memory_write_bytes) / sram_access; });
  std::optional<double> rf_per_byte;
  if (t.register_file.energy_pj && t.register_file.access_bytes) rf_per_byte = *t.register_file.energy_pj / *t.register_file.access_bytes;
  const auto fifo_bytes_moved = [&](std::size_t u) {
    return static_cast<double>(f.units[u].fifo_pushes + f.units[u].fifo_pops) * d.ray_bytes;
  };
  charge_fifos(
      b, "ray_fifo", t.sram.read_energy_pj, rf_per_byte, "sram read_energy", units,
      [&](std::size_t u) { return static_cast<double>(d.units[u].fifo_bytes); },
      [&](std::size_t u) { return fifo_bytes_moved(u) / sram_access; }, fifo_bytes_moved);

  double config = 0, dram = 0, buffers = 0, stacks = 0, miss = 0;
  for (const UnitActivity& u : f.units) {
    config += static_cast<double>(u.config_write_bytes);
    dram += static_cast<double>(u.dram_bytes);
    buffers += static_cast<double>(u.buffer_access_bytes);
    stacks += static_cast<double>(u.stack_access_bytes);
    miss += static_cast<double>(u.miss_register_access_bytes);
  }
  const auto rf_access = t.register_file.access_bytes.value_or(1);
  b.charge("configuration", config / rf_access, t.register_file.energy_pj, "register_file energy");
  b.charge("pipeline_buffers", buffers / rf_access, t.register_file.energy_pj, "register_file energy");
  b.charge("traversal_stacks", stacks / rf_access, t.register_file.energy_pj, "register_file energy");
  b.charge("miss_registers", miss / rf_access, t.register_file.energy_pj, "register_file energy");

  // The bus and leakage scale with the area.
  const Cost area = area_mm2(t, d);
  bool area_complete = true;
  for (const auto& c : area.components) area_complete = area_complete && c.value.has_value();
  std::optional<double> wire;
  if (t.wire_pj_per_bit_mm) wire = *t.wire_pj_per_bit_mm * std::sqrt(area.total);  // per bit, across the die
  b.charge("bus", 8.0 * static_cast<double>(f.bus_bytes), wire, "wire energy");

  std::optional<double> dram_access;
  if (t.dram.energy_low_pj) dram_access = (*t.dram.energy_low_pj + *t.dram.energy_high_pj) / 2;
  b.charge("dram", dram / t.dram.access_bytes.value_or(1), dram_access, "dram energy");

  std::optional<double> leakage_pj_per_s;
  if (t.leakage_w_per_mm2) leakage_pj_per_s = *t.leakage_w_per_mm2 * area.total * 1e12;
  b.charge("leakage", f.frame_time_s, leakage_pj_per_s, "leakage power");
  if (!area_complete && ((f.bus_bytes && wire) || (f.frame_time_s > 0 && leakage_pj_per_s)))
    b.note("bus, leakage: the area they scale with has uncharged components: an under-estimate");
  precision_note(b, d);
  return finite(b.take(), t, "energy");
}

namespace {
template <typename T>
std::uint64_t memory_bytes(std::uint64_t triangles, std::uint64_t nodes, Kernel k) {
  return triangles * triangle_bytes<T>(k) + nodes * BvhNode<T>::kBytes;
}
}  // namespace

std::uint64_t object_memory_bytes(std::uint64_t triangles, std::uint64_t bvh_nodes, Kernel k, bool double_precision) {
  return double_precision ? memory_bytes<double>(triangles, bvh_nodes, k) : memory_bytes<float>(triangles, bvh_nodes, k);
}

std::uint64_t config_bytes(std::uint64_t spheres, bool double_precision) {
  return spheres * (double_precision ? Bytes<double>::sphere_config : Bytes<float>::sphere_config);
}

std::uint32_t ray_bytes(bool double_precision) {
  return double_precision ? Bytes<double>::ray : Bytes<float>::ray;
}

}  // namespace oprt
