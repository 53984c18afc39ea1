#include "arch/cycle_schedule.h"

#include <algorithm>
#include <map>
#include <sstream>
#include <stdexcept>

namespace oprt {

Schedule list_schedule(const OpGraph& g) {
  std::map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < g.ops.size(); ++i) {
    if (!index.emplace(g.ops[i].name, i).second)
      throw std::logic_error(g.name + ": duplicate op " + g.ops[i].name);
  }
  for (const Op& op : g.ops)
    for (const auto& in : op.in)
      if (!index.count(in)) throw std::logic_error(g.name + ": " + op.name + " reads unknown " + in);

  Schedule s;
  s.graph = &g;
  s.cycle.assign(g.ops.size(), 0);
  std::size_t left = g.ops.size();
  for (int cycle = 1; left > 0; ++cycle) {
    if (cycle > 10000) throw std::logic_error(g.name + ": dependency cycle");
    for (Fu fu : {Fu::adder, Fu::multiplier}) {
      for (std::size_t i = 0; i < g.ops.size(); ++i) {
        const Op& op = g.ops[i];
        if (op.fu != fu || s.cycle[i]) continue;
        const bool ready = std::all_of(op.in.begin(), op.in.end(), [&](const std::string& in) {
          const int c = s.cycle[index[in]];
          return c != 0 && c < cycle;  // results are available the cycle after
        });
        if (!ready) continue;
        s.cycle[i] = cycle;
        --left;
        break;
      }
    }
  }
  s.exit_cycle.assign(g.stages.size(), 0);
  for (std::size_t i = 0; i < g.ops.size(); ++i)
    if (g.ops[i].exit_stage >= 0)
      s.exit_cycle.at(g.ops[i].exit_stage) = std::max(s.exit_cycle[g.ops[i].exit_stage], s.cycle[i]);
  for (std::size_t k = 0; k < s.exit_cycle.size(); ++k)
    if (!s.exit_cycle[k]) throw std::logic_error(g.name + ": stage " + g.stages[k] + " has no exit op");
  return s;
}

namespace {
// A pipelined unit's schedule: several ops per kind in a cycle.
std::string modulo_table(const Schedule& s) {
  std::ostringstream out;
  const OpGraph& g = *s.graph;
  out << g.name << " (pipelined: a new instance every " << s.ii << (s.ii == 1 ? " cycle" : " cycles") << ", latency "
      << s.length() << ")\n  cycle  adders | multipliers | exit\n";
  for (int c = 1; c <= s.length(); ++c) {
    std::string add, mul, exits;
    for (std::size_t i = 0; i < s.cycle.size(); ++i) {
      if (s.cycle[i] != c) continue;
      std::string& col = g.ops[i].fu == Fu::adder ? add : mul;
      col += (col.empty() ? "" : " ") + g.ops[i].name;
    }
    for (std::size_t k = 0; k < s.exit_cycle.size(); ++k)
      if (s.exit_cycle[k] == c) exits += (exits.empty() ? "" : ", ") + g.stages[k];
    char row[32];
    std::snprintf(row, sizeof row, "  %5d  ", c);
    out << row << (add.empty() ? "-" : add) << " | " << (mul.empty() ? "-" : mul) << " | " << exits << "\n";
  }
  return out.str();
}
}  // namespace

std::string Schedule::table() const {
  if (ii > 0) return modulo_table(*this);
  std::ostringstream out;
  const int n = *std::max_element(cycle.begin(), cycle.end());
  out << graph->name << "\n  cycle  adder            multiplier       exit\n";
  for (int c = 1; c <= n; ++c) {
    std::string add = "-", mul = "-", exits;
    for (std::size_t i = 0; i < cycle.size(); ++i) {
      if (cycle[i] != c) continue;
      (graph->ops[i].fu == Fu::adder ? add : mul) = graph->ops[i].name;
    }
    for (std::size_t k = 0; k < exit_cycle.size(); ++k)
      if (exit_cycle[k] == c) exits += (exits.empty() ? "" : ", ") + graph->stages[k];
    char row[128];
    std::snprintf(row, sizeof row, "  %5d  %-16s %-16s %s\n", c, add.c_str(), mul.c_str(), exits.c_str());
    out << row;
  }
  return out.str();
}

FpUnits full_units(const OpGraph& g, int add_latency, int multiply_latency) {
  FpUnits u{0, 0, add_latency, multiply_latency};
  for (const Op& op : g.ops) ++(op.fu == Fu::adder ? u.adders : u.multipliers);
  return u;
}

Schedule modulo_schedule(const OpGraph& g, const FpUnits& units) {
  if (units.add_latency < 1 || units.multiply_latency < 1) throw std::logic_error(g.name + ": FP latencies must be >= 1");
  std::map<std::string, std::size_t> index;
  for (std::size_t i = 0; i < g.ops.size(); ++i)
    if (!index.emplace(g.ops[i].name, i).second) throw std::logic_error(g.name + ": duplicate op " + g.ops[i].name);
  int adds = 0, muls = 0;
  for (const Op& op : g.ops) {
    ++(op.fu == Fu::adder ? adds : muls);
    for (const auto& in : op.in)
      if (!index.count(in)) throw std::logic_error(g.name + ": " + op.name + " reads unknown " + in);
  }
  if ((adds && units.adders < 1) || (muls && units.multipliers < 1))
    throw std::logic_error(g.name + ": needs at least one adder and one multiplier");
  const auto ceil_div = [](int a, int b) { return b > 0 ? (a + b - 1) / b : 0; };
  Schedule s;
  s.graph = &g;
  s.ii = std::max({1, ceil_div(adds, units.adders), ceil_div(muls, units.multipliers)});
  s.cycle.assign(g.ops.size(), 0);
  // Modulo reservation table: per kind, ops placed in each slot (cycle mod II).
  std::vector<int> used_add(s.ii, 0), used_mul(s.ii, 0);
  const auto latency = [&](std::size_t i) { return g.ops[i].fu == Fu::adder ? units.add_latency : units.multiply_latency; };
  std::size_t left = g.ops.size();
  while (left > 0) {
    const std::size_t before = left;
    for (std::size_t i = 0; i < g.ops.size(); ++i) {  // program order, each op once its inputs are placed
      if (s.cycle[i]) continue;
      int earliest = 1;
      bool ready = true;
      for (const auto& in : g.ops[i].in) {
        const std::size_t j = index[in];
        if (!s.cycle[j]) {
          ready = false;
          break;
        }
        earliest = std::max(earliest, s.cycle[j] + latency(j));
      }
      if (!ready) continue;
      const bool adder = g.ops[i].fu == Fu::adder;
      std::vector<int>& used = adder ? used_add : used_mul;
      const int capacity = adder ? units.adders : units.multipliers;
      for (int c = earliest; c < earliest + s.ii; ++c) {
        if (used[c % s.ii] >= capacity) continue;
        ++used[c % s.ii];
        s.cycle[i] = c;
        --left;
        break;
      }
      if (!s.cycle[i]) throw std::logic_error(g.name + ": no free slot for " + g.ops[i].name);  // cannot happen
    }
    if (left == before) throw std::logic_error(g.name + ": dependency cycle");
  }
  s.exit_cycle.assign(g.stages.size(), 0);
  for (std::size_t i = 0; i < g.ops.size(); ++i) {
    const int k = g.ops[i].exit_stage;
    if (k >= 0) s.exit_cycle.at(k) = std::max(s.exit_cycle[k], s.cycle[i] + latency(i) - 1);
  }
  for (std::size_t k = 0; k < s.exit_cycle.size(); ++k)
    if (!s.exit_cycle[k]) throw std::logic_error(g.name + ": stage " + g.stages[k] + " has no exit op");
  // The unit's latency covers every op, not only the exits (a later stage's check may
  // complete before an unrelated op it does not need).
  int last = 0;
  for (std::size_t i = 0; i < g.ops.size(); ++i) last = std::max(last, s.cycle[i] + latency(i) - 1);
  s.exit_cycle.back() = std::max(s.exit_cycle.back(), last);
  return s;
}

namespace {
Op add(std::string n, std::vector<std::string> in = {}, int exit = -1) { return {std::move(n), Fu::adder, std::move(in), exit, false}; }
Op mul(std::string n, std::vector<std::string> in = {}, int exit = -1) { return {std::move(n), Fu::multiplier, std::move(in), exit, false}; }
Op cmp(std::string n, std::vector<std::string> in = {}, int exit = -1) { return {std::move(n), Fu::adder, std::move(in), exit, true}; }
}  // namespace

// L = c - o, tca = L.d, hit if (L.L - r^2) - tca^2 <= 0 (r^2 folded in early; the final
// sign is free). 9 adds and 7 multiplies: 10 cycles, the best any schedule of this graph
// achieves (exhaustive search); the paper's Table 1 states 9.
const OpGraph& sphere_textbook_graph() {
  static const OpGraph g{"sphere test (textbook, paper Table 1 form)", {"done"}, {
      add("Lx"), add("Ly"), add("Lz"),
      mul("Lx*dx", {"Lx"}), mul("Ly*dy", {"Ly"}), mul("Lz*dz", {"Lz"}),
      mul("Lx*Lx", {"Lx"}), mul("Ly*Ly", {"Ly"}), mul("Lz*Lz", {"Lz"}),
      add("tca'", {"Lx*dx", "Ly*dy"}), add("tca", {"tca'", "Lz*dz"}), mul("tca^2", {"tca"}),
      add("LL'", {"Lx*Lx", "Ly*Ly"}), add("LL", {"LL'", "Lz*Lz"}), add("LL-r2", {"LL"}),
      cmp("LL-r2-tca2", {"LL-r2", "tca^2"}, 0)}};
  return g;
}

// f = o - c, b = f.d, l = f - b d, hit if (l.l - r^2) <= 0 and (b <= 0 or the origin is
// inside: |f|^2 = |l|^2 + b^2 <= r^2, no cancellation since both terms are positive).
const OpGraph& sphere_stable_graph() {
  static const OpGraph g{"sphere test (stable, Ray Tracing Gems ch. 7)", {"done"}, {
      add("fx"), add("fy"), add("fz"),
      mul("fx*dx", {"fx"}), mul("fy*dy", {"fy"}), mul("fz*dz", {"fz"}),
      add("b'", {"fx*dx", "fy*dy"}), add("b", {"b'", "fz*dz"}),
      mul("b*dx", {"b"}), mul("b*dy", {"b"}), mul("b*dz", {"b"}),
      add("lx", {"fx", "b*dx"}), add("ly", {"fy", "b*dy"}), add("lz", {"fz", "b*dz"}),
      mul("lx*lx", {"lx"}), mul("ly*ly", {"ly"}), mul("lz*lz", {"lz"}), mul("b*b", {"b"}),
      add("ll'", {"lx*lx", "ly*ly"}), add("ll'-r2", {"ll'"}), add("ll-r2", {"ll'-r2", "lz*lz"}, 0),
      cmp("ll-r2+b2", {"ll-r2", "b*b"}, 0)}};
  return g;
}

namespace {
// One component of a matrix-vector product: 3 multiplies and 2 adds, a third add for the
// translation of a point. `exit` marks the last add (-1: none).
void push_row(OpGraph& g, const std::string& out, bool translate, int exit) {
  g.ops.push_back(mul(out + "0"));
  g.ops.push_back(mul(out + "1"));
  g.ops.push_back(mul(out + "2"));
  g.ops.push_back(add(out + "01", {out + "0", out + "1"}));
  if (translate) {
    g.ops.push_back(add(out + "012", {out + "01", out + "2"}));
    g.ops.push_back(add(out, {out + "012"}, exit));
  } else {
    g.ops.push_back(add(out, {out + "01", out + "2"}, exit));
  }
}
}  // namespace

// o' = L o + t (3 x (3 multiplies, 3 adds)), d' = L d (3 x (3 multiplies, 2 adds)).
const OpGraph& transform_graph() {
  static const OpGraph g = [] {
    OpGraph t{"ray transform into the local frame", {"done"}, {}};
    for (const char* r : {"x", "y", "z"}) push_row(t, std::string("o'") + r, true, 0);
    for (const char* r : {"x", "y", "z"}) push_row(t, std::string("d'") + r, false, 0);
    return t;
  }();
  return g;
}

// Moller-Trumbore with the stored normal n = e1 x e2 (geom/triangle.h):
//   det = -d.n                      exit 'det' if zero (a flag: free)
//   tv = o - v0, c = tv x d
//   u = e2.c; exit 'u' if u < 0 (free) or det - u < 0
//   v = -e1.c; exit 'v' if v < 0 (free) or (det - u) - v < 0
//   t' = tv.n; then one datapath for both ray kinds: t' < tmax det (the ray's extent) and
//   t' det_best < t'_best det (the unit's nearest hit so far, kept as a fraction so no
//   division is needed; the GPP divides once per ray). Exit 'done'.
const OpGraph& moller_graph() {
  static const OpGraph g{"triangle test (Moller-Trumbore, stored normal)", {"det", "u", "v", "done"}, {
      mul("dx*nx"), mul("dy*ny"), mul("dz*nz"), add("tvx"), add("tvy"),
      add("det'", {"dx*nx", "dy*ny"}), add("det", {"det'", "dz*nz"}, 0), add("tvz"),
      mul("tvy*dz", {"tvy"}), mul("tvz*dy", {"tvz"}), mul("tvz*dx", {"tvz"}),
      mul("tvx*dz", {"tvx"}), mul("tvx*dy", {"tvx"}), mul("tvy*dx", {"tvy"}),
      add("cx", {"tvy*dz", "tvz*dy"}), add("cy", {"tvz*dx", "tvx*dz"}), add("cz", {"tvx*dy", "tvy*dx"}),
      mul("e2x*cx", {"cx"}), mul("e2y*cy", {"cy"}), mul("e2z*cz", {"cz"}),
      add("u'", {"e2x*cx", "e2y*cy"}), add("u", {"u'", "e2z*cz"}), add("det-u", {"u", "det"}, 1),
      mul("e1x*cx", {"cx"}), mul("e1y*cy", {"cy"}), mul("e1z*cz", {"cz"}),
      add("v'", {"e1x*cx", "e1y*cy"}), add("v", {"v'", "e1z*cz"}), cmp("det-u-v", {"det-u", "v"}, 2),
      mul("tvx*nx", {"tvx"}), mul("tvy*ny", {"tvy"}), mul("tvz*nz", {"tvz"}),
      add("t''", {"tvx*nx", "tvy*ny"}), add("t'", {"t''", "tvz*nz"}),
      mul("tmax*det", {"det"}), mul("t'best*det", {"det"}), mul("t'*detbest", {"t'"}),
      cmp("tmax*det-t'", {"t'", "tmax*det"}, 3), cmp("nearest?", {"t'*detbest", "t'best*det"}, 3)}};
  return g;
}

// The transform as the watertight kernel needs it: the same 18 multiplies and 15 adds, d'
// first, then the choice of the ray's dominant axis kz = argmax |d'| (two comparisons on the
// adder, absolute values are free), which the triangle test uses to permute coordinates
// (routing, free). Computing d' first delays o' by a cycle: 20, one more than Table 1.
const OpGraph& transform_watertight_graph() {
  static const OpGraph g = [] {
    OpGraph t{"ray transform into the local frame, with the dominant axis (watertight)", {"done"}, {}};
    for (const char* r : {"x", "y", "z"}) push_row(t, std::string("d'") + r, false, -1);
    t.ops.push_back(cmp("|d'x|-|d'y|", {"d'x", "d'y"}));
    t.ops.push_back(cmp("max-|d'z|", {"|d'x|-|d'y|", "d'z"}, 0));
    for (const char* r : {"x", "y", "z"}) push_row(t, std::string("o'") + r, true, 0);
    return t;
  }();
  return g;
}

// Watertight (Woop, Benthin, Wald, JCGT 2013; geom/watertight.h), without a divider: in
// coordinates permuted so that z is the ray's dominant axis, each vertex is translated to
// the ray origin (A = v0 - o, B = v1 - o, C = v2 - o) and sheared along the ray by
// x' = dz x - dx z, y' = dz y - dy z (the JCGT shear multiplied through by dz). Then
//   U = b'x c'y - b'y c'x, V = c'x a'y - c'y a'x, W = a'x b'y - a'y b'x
// exit 'uv' if U and V have strictly opposite signs (sign flags: free), exit 'w' if W
// disagrees with them, exit 'det' if det = U + V + W is zero (its flag; with the signs
// agreeing, only when all three are zero: a degenerate triangle, or a ray in its plane).
// Then T = U Az + V Bz + W Cz and D = dz det, so that
// t = T / D; the last stage is the same datapath as Moller's: T < tmax D and
// T D_best < T_best D (the nearest so far, kept as a fraction). Exit 'done'.
const OpGraph& watertight_graph() {
  static const OpGraph g{"triangle test (watertight, division-free shear)", {"uv", "w", "det", "done"}, {
      add("Bx"), add("Bz"), add("By"), add("Cx"), add("Cz"), add("Cy"), add("Ax"), add("Az"), add("Ay"),
      mul("dz*Bx", {"Bx"}), mul("dx*Bz", {"Bz"}), mul("dz*By", {"By"}), mul("dy*Bz", {"Bz"}),
      add("b'x", {"dz*Bx", "dx*Bz"}), add("b'y", {"dz*By", "dy*Bz"}),
      mul("dz*Cx", {"Cx"}), mul("dx*Cz", {"Cz"}), mul("dz*Cy", {"Cy"}), mul("dy*Cz", {"Cz"}),
      add("c'x", {"dz*Cx", "dx*Cz"}), add("c'y", {"dz*Cy", "dy*Cz"}),
      mul("b'x*c'y", {"b'x", "c'y"}), mul("b'y*c'x", {"b'y", "c'x"}), add("U", {"b'x*c'y", "b'y*c'x"}),
      mul("dz*Ax", {"Ax"}), mul("dx*Az", {"Az"}), mul("dz*Ay", {"Ay"}), mul("dy*Az", {"Az"}),
      add("a'x", {"dz*Ax", "dx*Az"}), add("a'y", {"dz*Ay", "dy*Az"}),
      mul("c'x*a'y", {"c'x", "a'y"}), mul("c'y*a'x", {"c'y", "a'x"}), add("V", {"c'x*a'y", "c'y*a'x"}, 0),
      mul("a'x*b'y", {"a'x", "b'y"}), mul("a'y*b'x", {"a'y", "b'x"}), add("W", {"a'x*b'y", "a'y*b'x"}, 1),
      add("det'", {"U", "V"}), add("det", {"det'", "W"}, 2),
      mul("U*Az", {"U"}), mul("V*Bz", {"V"}), mul("W*Cz", {"W"}),
      add("T'", {"U*Az", "V*Bz"}), add("T", {"T'", "W*Cz"}),
      mul("D=dz*det", {"det"}), mul("tmax*D", {"D=dz*det"}), mul("Tbest*D", {"D=dz*det"}), mul("T*Dbest", {"T"}),
      cmp("tmax*D-T", {"T", "tmax*D"}, 3), cmp("nearest?", {"T*Dbest", "Tbest*D"}, 3)}};
  return g;
}

// The BVH's box set-up, once per entered sphere after the transform: the local ray's
// reciprocal direction 1/d (geom/bvh.h box_ray). The unit has no divider: Newton-Raphson,
// r' = r (2 - d r), from a seed read from a small ROM indexed by d's leading mantissa bits
// (a table lookup, free like a flag), two iterations per component (an 8-bit seed gives
// 16, then 32 bits: float's 24 with margin; a double datapath needs a third, 6 more
// cycles: set costs.box_setup). The model takes the result to be the correctly rounded
// 1/d, which kBoxSlack's argument assumes; a datapath must deliver that or widen the slack.
// 12 multiplies, 6 adds: 12 cycles, the multiplier never idle after the first.
const OpGraph& box_setup_graph() {
  static const OpGraph g = [] {
    OpGraph t{"box set-up (reciprocal direction, Newton-Raphson)", {"done"}, {}};
    const char* ax[] = {"x", "y", "z"};
    for (const char* a : ax) t.ops.push_back(mul(std::string("d*r0") + a));
    for (const char* a : ax) t.ops.push_back(add(std::string("2-d*r0") + a, {std::string("d*r0") + a}));
    for (const char* a : ax) t.ops.push_back(mul(std::string("r1") + a, {std::string("2-d*r0") + a}));
    for (const char* a : ax) t.ops.push_back(mul(std::string("d*r1") + a, {std::string("r1") + a}));
    for (const char* a : ax) t.ops.push_back(add(std::string("2-d*r1") + a, {std::string("d*r1") + a}));
    for (const char* a : ax)
      t.ops.push_back(mul(std::string("1/d") + a, {std::string("r1") + a, std::string("2-d*r1") + a}, 0));
    return t;
  }();
  return g;
}

// Ray-box slab test (geom/bvh.h hit_box): per axis the near and far bounds (chosen by the
// sign of 1/d: a multiplexer, free) minus the origin, times 1/d; t0 = max of the nears and
// 0 (the 0 is a sign flag), t1 = min of the fars and the limit (the nearest hit so far, or
// tmax); hit if t0 <= K t1 (K = kBoxSlack, one multiply). A max or min is a comparison (a
// subtraction) and a multiplexer. 12 adds and 7 multiplies: 13 cycles, the adder the
// bottleneck; the comparisons come last, so an earlier exit would save little.
const OpGraph& box_graph() {
  static const OpGraph g{"box test (slabs, conservative)", {"done"}, {
      add("nx-ox"), add("fx-ox"), add("ny-oy"), add("fy-oy"), add("nz-oz"), add("fz-oz"),
      mul("tnx", {"nx-ox"}), mul("tfx", {"fx-ox"}), mul("tny", {"ny-oy"}), mul("tfy", {"fy-oy"}),
      mul("tnz", {"nz-oz"}), mul("tfz", {"fz-oz"}),
      cmp("tnx-tny", {"tnx", "tny"}), cmp("tfx-tfy", {"tfx", "tfy"}),
      cmp("t0'-tnz", {"tnx-tny", "tnz"}), cmp("t1'-tfz", {"tfx-tfy", "tfz"}), cmp("t1''-limit", {"t1'-tfz"}),
      mul("K*t1", {"t1''-limit"}), cmp("t0-K*t1", {"t0'-tnz", "K*t1"}, 0)}};
  return g;
}

// A node of the unit's tree over its spheres (--top bvh, ref/top_tree.h): a world-space box
// tested against the world ray. The ray's reciprocal direction comes with the ray (the GPP
// computes it once per ray, hw/payloads.h), so there is no set-up; the limit is the unit's
// nearest hit so far, or a shadow ray's tmax, and a node beyond it is skipped. The same slab
// test as a sphere's BVH node, the adder the bottleneck: 13 cycles.
const OpGraph& top_node_graph() {
  static const OpGraph g = [] {
    OpGraph t = box_graph();
    t.name = "top-level node test (world box, reciprocal sent with the ray)";
    return t;
  }();
  return g;
}

// A pipelined unit that walks a BVH inside the sphere forms the reciprocal direction in its
// transform unit: the transform's graph followed by the box set-up's, each set-up chain
// starting from its axis of d'. One graph, modulo scheduled as one.
const OpGraph& transform_box_setup_graph(Kernel k) {
  auto build = [](const OpGraph& transform) {
    OpGraph t = transform;
    t.name = transform.name + ", then the box set-up";
    for (Op op : box_setup_graph().ops) {
      if (op.in.empty()) op.in.push_back(std::string("d'") + op.name.back());  // d*r0x needs d'x
      t.ops.push_back(std::move(op));
    }
    return t;
  };
  static const OpGraph moller = build(transform_graph());
  static const OpGraph watertight = build(transform_watertight_graph());
  return k == Kernel::watertight ? watertight : moller;
}

}  // namespace oprt
