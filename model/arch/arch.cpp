#include "arch/arch.h"

#include "base/json_in.h"
#include "base/numbers.h"
#include "geom/ray.h"  // kMaxDepth

#include <cctype>
#include <cmath>
#include <sstream>
#include <cstdlib>
#include <functional>

namespace oprt {

const char* to_string(Level l) { return l == Level::at ? "at" : l == Level::lt ? "lt" : "analytic"; }
const char* to_string(BusModel b) { return b == BusModel::ideal ? "ideal" : "shared"; }
const char* to_string(LtArbitration b) {
  return b == LtArbitration::sync ? "sync" : b == LtArbitration::calendar ? "calendar" : "busy_until";
}
const char* to_string(MemoryModel m) { return m == MemoryModel::ideal ? "ideal" : "latency"; }
const char* to_string(CacheReplacement r) {
  return r == CacheReplacement::lru ? "lru" : r == CacheReplacement::fifo ? "fifo" : "random";
}
const char* to_string(DramPath p) {
  return p == DramPath::channel ? "channel" : p == DramPath::bus ? "bus" : "external";
}
const char* to_string(IuModel m) { return m == IuModel::serial ? "serial" : "pipelined"; }

double parse_time_ns(const std::string& text, const std::string& what) {
  return static_cast<double>(parse_time_ps(text, false, {what, text})) / 1000;
}

namespace {
template <typename E>
E choose(const JsonIn& j, std::initializer_list<std::pair<const char*, E>> options) {
  const std::string v = j.string();
  std::string list;
  for (const auto& [name, e] : options) {
    if (v == name) return e;
    list += std::string(list.empty() ? "" : ", ") + name;
  }
  j.fail("unknown value \"" + v + "\" (expected one of: " + list + ")");
}
std::string one_of(const JsonIn& j, std::initializer_list<const char*> options) {
  const std::string v = j.string();
  std::string list;
  for (const char* o : options) {
    if (v == o) return v;
    list += std::string(list.empty() ? "" : ", ") + o;
  }
  j.fail("unknown value \"" + v + "\" (expected one of: " + list + ")");
}
int cycles(const JsonIn& j) { return static_cast<int>(j.integer(0, 1000000)); }

// "transform" and "triangle" (one cost per exit stage, in the kernel's stage order).
void read_kernel_costs(const JsonIn& j, Kernel k, KernelCosts& c) {
  if (auto v = j.find("transform")) c.transform = cycles(*v);
  if (auto v = j.find("triangle")) {
    auto items = v->items();
    const char* const* names = stage_names(k);
    if (items.size() != kTriStages)
      v->fail("expected " + std::to_string(kTriStages) + " cycle counts (exit stages " + names[0] + ", " + names[1] +
              ", " + names[2] + ", " + names[3] + "), found " + std::to_string(items.size()));
    for (int s = 0; s < kTriStages; ++s) c.tri_stage[s] = cycles(items[s]);
  }
}

nlohmann::json stage_costs_json(const KernelCosts& c) {
  return {c.tri_stage[0], c.tri_stage[1], c.tri_stage[2], c.tri_stage[3]};
}

void read_iu(const JsonIn& j, IuConfig& iu) {
  j.only_keys({"model", "rays_in_flight", "queue_depth", "stack", "fp_latency", "node", "sphere", "transform", "box",
               "triangle"});
  if (auto v = j.find("model"))
    iu.model = choose<IuModel>(*v, {{"serial", IuModel::serial}, {"pipelined", IuModel::pipelined}});
  iu.rays_in_flight = static_cast<int>(j.integer_or("rays_in_flight", iu.rays_in_flight, 1, 4096));
  if (auto v = j.find("queue_depth"))
    v->fail("no longer a setting: a pipelined unit's units pick among its rays in flight (iu.rays_in_flight), "
            "docs/cycle-model.md");
  if (auto st = j.find("stack")) {
    st->only_keys({"depth", "overflow_cycles"});
    iu.stack_depth = static_cast<int>(st->integer_or("depth", iu.stack_depth, 1, 1024));
    iu.stack_overflow_cycles = static_cast<int>(st->integer_or("overflow_cycles", iu.stack_overflow_cycles, 0, 1 << 20));
  }
  if (auto l = j.find("fp_latency")) {
    l->only_keys({"add", "multiply"});
    iu.add_latency = static_cast<int>(l->integer_or("add", iu.add_latency, 1, 64));
    iu.multiply_latency = static_cast<int>(l->integer_or("multiply", iu.multiply_latency, 1, 64));
  }
  for (auto [key, unit] : {std::pair{"node", &iu.node}, {"sphere", &iu.sphere}, {"transform", &iu.transform},
                           {"box", &iu.box}, {"triangle", &iu.triangle}}) {
    if (auto u = j.find(key)) {
      u->only_keys({"adders", "multipliers"});
      unit->adders = static_cast<int>(u->integer_or("adders", unit->adders, 0, 1024));
      unit->multipliers = static_cast<int>(u->integer_or("multipliers", unit->multipliers, 0, 1024));
    }
  }
}

}  // namespace

// "auto", "off" or a number of copies from 1 (off) to 65535.
int replicate_named(const std::string& text, const std::string& where) {
  if (text == "auto") return Arch::kReplicateAuto;
  if (text == "off") return 0;
  std::size_t end = 0;
  long long n = -1;
  try {
    n = std::stoll(text, &end);
  } catch (const std::exception&) {
    end = 0;
  }
  if (end != text.size() || text.empty() || !std::isdigit(static_cast<unsigned char>(text[0])) || n < 1 || n > 65535)
    throw InputError(where, text, "expected auto, off or a number of copies from 1 to 65535");
  return n == 1 ? 0 : static_cast<int>(n);
}

namespace {

// "balance": a policy's name, or {"policy": NAME, "locality": F, "replicate": R} (each key optional).
void read_balance(const JsonIn& j, Arch& a) {
  const std::initializer_list<const char*> policies = {"paper", "round_robin", "sa_n", "spatial", "feedback", "view"};
  if (!j.is_object()) {
    a.balance = one_of(j, policies);
    return;
  }
  j.only_keys({"policy", "locality", "replicate"});
  if (auto v = j.find("policy")) a.balance = one_of(*v, policies);
  if (auto v = j.find("locality")) a.locality = v->number(0, 1);
  if (auto v = j.find("replicate")) {
    if (v->is_string()) {
      a.replicate = replicate_named(v->string(), a.source + ": /balance/replicate");
    } else {
      const int n = static_cast<int>(v->integer(1, 65535));
      a.replicate = n == 1 ? 0 : n;
    }
  }
}

// "route": a policy's name, or {"policy", "transfer", "wave", "lanes", "bound", "adders", "multipliers"}.
void read_route(const JsonIn& j, Arch& a) {
  const std::initializer_list<const char*> policies = {"broadcast", "multicast", "ordered"};
  if (!j.is_object()) {
    a.route.policy = one_of(j, policies);
    return;
  }
  j.only_keys({"policy", "transfer", "wave", "lanes", "bound", "adders", "multipliers"});
  if (auto v = j.find("policy")) a.route.policy = one_of(*v, policies);
  if (auto v = j.find("transfer")) a.route.transfer = one_of(*v, {"mask", "per_unit"});
  a.route.wave = static_cast<int>(j.integer_or("wave", a.route.wave, 1, 65536));
  a.route.lanes = static_cast<int>(j.integer_or("lanes", a.route.lanes, 1, 65536));
  if (auto v = j.find("bound")) a.route.bound = one_of(*v, {"unit", "sphere"});
  a.route.units.adders = static_cast<int>(j.integer_or("adders", a.route.units.adders, 0, 1024));
  a.route.units.multipliers = static_cast<int>(j.integer_or("multipliers", a.route.units.multipliers, 0, 1024));
}

nlohmann::json iu_json(const IuConfig& iu) {
  const auto unit = [](const IuConfig::Unit& u) { return nlohmann::json{{"adders", u.adders}, {"multipliers", u.multipliers}}; };
  return {{"model", to_string(iu.model)},
          {"rays_in_flight", iu.rays_in_flight},
          {"stack", {{"depth", iu.stack_depth}, {"overflow_cycles", iu.stack_overflow_cycles}}},
          {"fp_latency", {{"add", iu.add_latency}, {"multiply", iu.multiply_latency}}},
          {"node", unit(iu.node)},
          {"sphere", unit(iu.sphere)},
          {"transform", unit(iu.transform)},
          {"box", unit(iu.box)},
          {"triangle", unit(iu.triangle)}};
}
}  // namespace

void check_sram(const Arch& a, const std::string& file, const std::string& place) {
  const std::uint64_t set = std::uint64_t(a.memory.cache.line_bytes) * a.memory.cache.ways;
  if (a.memory.sram_bytes != 0 && a.memory.sram_bytes < set)
    throw InputError(file, place,
                     "an object memory smaller than one cache set (line_bytes x ways = " + std::to_string(set) +
                         " bytes) cannot be a cache");
}

Arch arch_from_json(const nlohmann::json& doc, const std::string& file) {
  const JsonIn root(doc, file);
  root.only_keys({"format", "comment", "clock_mhz", "ius", "costs", "ray_fifo_depth", "bus", "memory", "gpp",
                  "level", "quantum", "balance", "subdivide", "split_rule", "split", "accel", "top", "route", "kernel",
                  "precision", "sync_every_ray", "iu"});
  const std::string format = root.at("format").string();
  if (format != "oprt-arch/1") root.at("format").fail("unsupported format \"" + format + "\" (expected oprt-arch/1)");
  Arch a;
  a.source = file;
  a.clock_mhz = root.number_or("clock_mhz", a.clock_mhz, 1e-3, 1e6);
  a.ius = static_cast<int>(root.integer_or("ius", a.ius, 1, 65536));
  if (auto c = root.find("costs")) {
    c->only_keys({"sphere", "transform", "triangle", "watertight", "box", "box_setup", "node"});
    if (auto v = c->find("sphere")) a.costs.sphere = cycles(*v);
    if (auto v = c->find("node")) a.costs.node = cycles(*v);
    if (auto v = c->find("box")) a.costs.box = cycles(*v);
    if (auto v = c->find("box_setup")) a.costs.box_setup = cycles(*v);
    read_kernel_costs(*c, Kernel::moller, a.costs.moller);
    if (auto w = c->find("watertight")) {
      w->only_keys({"transform", "triangle"});
      read_kernel_costs(*w, Kernel::watertight, a.costs.watertight);
    }
  }
  a.fifo_depth = static_cast<int>(root.integer_or("ray_fifo_depth", a.fifo_depth, 0, 1 << 24));
  if (auto b = root.find("bus")) {
    b->only_keys({"model", "bytes_per_cycle", "arbitration_cycles", "lt_arbitration"});
    a.bus.model = choose<BusModel>(b->at("model"), {{"ideal", BusModel::ideal}, {"shared", BusModel::shared}});
    a.bus.bytes_per_cycle = static_cast<int>(b->integer_or("bytes_per_cycle", a.bus.bytes_per_cycle, 1, 1 << 20));
    a.bus.arbitration_cycles = static_cast<int>(b->integer_or("arbitration_cycles", a.bus.arbitration_cycles, 0, 1 << 20));
    if (auto v = b->find("lt_arbitration"))
      a.bus.lt_arbitration = choose<LtArbitration>(
          *v, {{"sync", LtArbitration::sync}, {"calendar", LtArbitration::calendar}, {"busy_until", LtArbitration::busy_until}});
  }
  if (auto m = root.find("memory")) {
    m->only_keys({"model", "latency_cycles", "bytes_per_cycle", "sram_bytes", "cache", "dram"});
    if (auto v = m->find("model"))
      a.memory.model = choose<MemoryModel>(*v, {{"ideal", MemoryModel::ideal}, {"latency", MemoryModel::latency}});
    a.memory.latency_cycles = static_cast<int>(m->integer_or("latency_cycles", a.memory.latency_cycles, 0, 1 << 20));
    a.memory.bytes_per_cycle = static_cast<int>(m->integer_or("bytes_per_cycle", a.memory.bytes_per_cycle, 1, 1 << 20));
    a.memory.sram_bytes = m->bytes_or("sram_bytes", 0, kMaxSramBytes);
    if (auto c = m->find("cache")) {
      c->only_keys({"line_bytes", "ways", "replacement", "misses_outstanding"});
      if (auto v = c->find("line_bytes")) {
        const auto n = v->integer(16, 1 << 16);
        if (n & (n - 1)) v->fail("expected a power of two");
        a.memory.cache.line_bytes = static_cast<int>(n);
      }
      a.memory.cache.ways = static_cast<int>(c->integer_or("ways", a.memory.cache.ways, 1, 1024));
      if (auto v = c->find("replacement"))
        a.memory.cache.replacement = choose<CacheReplacement>(
            *v, {{"lru", CacheReplacement::lru}, {"fifo", CacheReplacement::fifo}, {"random", CacheReplacement::random}});
      a.memory.cache.misses_outstanding =
          static_cast<int>(c->integer_or("misses_outstanding", a.memory.cache.misses_outstanding, 1, 1024));
    }
    if (auto d = m->find("dram")) {
      d->only_keys({"latency_cycles", "bytes_per_cycle", "units_per_channel", "path"});
      a.memory.dram.latency_cycles = static_cast<int>(d->integer_or("latency_cycles", a.memory.dram.latency_cycles, 0, 1 << 20));
      a.memory.dram.bytes_per_cycle =
          static_cast<int>(d->integer_or("bytes_per_cycle", a.memory.dram.bytes_per_cycle, 1, 1 << 20));
      a.memory.dram.units_per_channel =
          static_cast<int>(d->integer_or("units_per_channel", a.memory.dram.units_per_channel, 1, 65536));
      if (auto v = d->find("path"))
        a.memory.dram.path = choose<DramPath>(*v, {{"channel", DramPath::channel}, {"bus", DramPath::bus}, {"external", DramPath::external}});
    }
    check_sram(a, file, "/memory/sram_bytes");
  }
  if (auto g = root.find("gpp")) {
    g->only_keys({"cycles_per_ray", "cycles_per_hit", "cycles_per_node", "depth"});
    a.gpp.depth = static_cast<int>(g->integer_or("depth", -1, 0, kMaxDepth));
    a.gpp.cycles_per_ray = static_cast<int>(g->integer_or("cycles_per_ray", 0, 0, 1 << 20));
    a.gpp.cycles_per_hit = static_cast<int>(g->integer_or("cycles_per_hit", 0, 0, 1 << 20));
    a.gpp.cycles_per_node = static_cast<int>(g->integer_or("cycles_per_node", a.gpp.cycles_per_node, 0, 1 << 20));
  }
  if (auto v = root.find("level"))
    a.level = choose<Level>(*v, {{"at", Level::at}, {"lt", Level::lt}, {"analytic", Level::analytic}});
  if (auto v = root.find("quantum")) a.quantum_ns = parse_time_ps(v->string(), false, {file, v->place()}) / 1000.0;
  if (auto v = root.find("balance")) read_balance(*v, a);
  a.subdivide = static_cast<int>(root.integer_or("subdivide", a.subdivide, 1, 4096));
  if (auto v = root.find("split_rule")) a.split_rule = one_of(*v, {"balanced", "median"});
  if (auto v = root.find("split")) a.split = one_of(*v, {"count", "extent"});
  if (auto v = root.find("accel")) a.accel = one_of(*v, {"brute", "bvh"});
  if (auto v = root.find("top")) a.top = one_of(*v, {"flat", "bvh"});
  if (auto v = root.find("route")) read_route(*v, a);
  if (auto v = root.find("kernel")) a.kernel = *kernel_named(one_of(*v, {"moller", "watertight"}));
  if (auto v = root.find("precision")) a.precision = one_of(*v, {"float", "double"});
  a.sync_every_ray = root.boolean_or("sync_every_ray", a.sync_every_ray);
  if (auto v = root.find("iu")) read_iu(*v, a.iu);
  return a;
}

void check_arch(const Arch& a, const std::function<std::string(const std::string& key)>& origin) {
  if (a.locality && !a.balance_takes_locality()) {
    const std::string problem = "only spatial and feedback take a locality (tight unit bounds against balance)";
    // Named by where each setting came from (a flag or the file) when the caller knows.
    if (origin) throw InputError(origin("balance.locality") + " with " + origin("balance"), "", problem);
    throw InputError(a.source, "balance.locality with balance " + a.balance, problem);
  }
  // Every combination of the unit, its acceleration, the tree over its spheres and its
  // memory is modelled at every level: nothing else to refuse.
}

Arch load_arch(const std::string& path) { return arch_from_json(JsonIn::parse_file(path), path); }

namespace {
nlohmann::json without_locality(const Arch& a) {
  return {{"source", a.source},
          {"clock_mhz", a.clock_mhz},
          {"ius", a.ius},
          {"costs", {{"sphere", a.costs.sphere}, {"transform", a.costs.moller.transform},
                     {"triangle", stage_costs_json(a.costs.moller)},
                     {"watertight", {{"transform", a.costs.watertight.transform},
                                     {"triangle", stage_costs_json(a.costs.watertight)}}},
                     {"box", a.costs.box}, {"box_setup", a.costs.box_setup}, {"node", a.costs.node}}},
          {"ray_fifo_depth", a.fifo_depth},
          {"bus", {{"model", to_string(a.bus.model)}, {"bytes_per_cycle", a.bus.bytes_per_cycle},
                   {"arbitration_cycles", a.bus.arbitration_cycles}, {"lt_arbitration", to_string(a.bus.lt_arbitration)}}},
          {"memory", {{"model", to_string(a.memory.model)}, {"latency_cycles", a.memory.latency_cycles},
                      {"bytes_per_cycle", a.memory.bytes_per_cycle}, {"sram_bytes", a.memory.sram_bytes},
                      {"cache", {{"line_bytes", a.memory.cache.line_bytes}, {"ways", a.memory.cache.ways},
                                 {"replacement", to_string(a.memory.cache.replacement)},
                                 {"misses_outstanding", a.memory.cache.misses_outstanding}}},
                      {"dram", {{"latency_cycles", a.memory.dram.latency_cycles},
                                {"bytes_per_cycle", a.memory.dram.bytes_per_cycle},
                                {"units_per_channel", a.memory.dram.units_per_channel},
                                {"path", to_string(a.memory.dram.path)}}}}},
          {"gpp", {{"cycles_per_ray", a.gpp.cycles_per_ray}, {"cycles_per_hit", a.gpp.cycles_per_hit},
                   {"cycles_per_node", a.gpp.cycles_per_node}}},
          {"level", to_string(a.level)},
          {"quantum_ns", a.quantum_ns},
          {"balance", a.balance},
          {"subdivide", a.subdivide},
          {"split_rule", a.split_rule},
          {"split", a.split},
          {"accel", a.accel},
          {"top", a.top},
          {"route", {{"policy", a.route.policy}, {"transfer", a.route.transfer}, {"wave", a.route.wave}, {"lanes", a.route.lanes}, {"bound", a.route.bound},
                     {"adders", a.route.units.adders}, {"multipliers", a.route.units.multipliers}}},
          {"kernel", to_string(a.kernel)},
          {"precision", a.precision},
          {"sync_every_ray", a.sync_every_ray},
          {"iu", iu_json(a.iu)}};
}
}  // namespace

nlohmann::json to_json(const Arch& a) {
  nlohmann::json j = without_locality(a);
  // Only where it applies (the records of the other policies stay as they were).
  if (a.balance == "spatial") j["locality"] = a.locality.value_or(kDefaultLocality);
  else if (a.balance == "feedback" && a.locality) j["locality"] = *a.locality;
  if (a.replicate) j["replicate"] = a.replicate == Arch::kReplicateAuto ? nlohmann::json("auto") : nlohmann::json(a.replicate);
  return j;
}

}  // namespace oprt
