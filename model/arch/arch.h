// The architecture being modelled: clock, number of intersection units, cycle costs, ray
// FIFO depth, bus, object memory and GPP costs, plus the run options an exploration varies
// (level, quantum, balance policy, subdivision, acceleration, kernel, precision). Read from
// an `oprt-arch/1` JSON file (docs/architecture-format.md); command-line flags override the
// file, the file overrides these defaults, which are the paper's ideal assumptions.
#pragma once

#include "arch/cycle_costs.h"

#include <cstdint>
#include <functional>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace oprt {

enum class BusModel { ideal, shared };
// How the shared bus arbitrates under temporal decoupling (`lt`; bus.h): `sync` (an
// initiator synchronises before each transfer: requests arrive in time order, as at `at`),
// `calendar` (requests up to a quantum ahead are slotted into the calendar of grants), or
// `busy_until` (the naive single busy-until time, kept only to measure the error it makes).
// All three are the same arbitration at `at`.
enum class LtArbitration { sync, calendar, busy_until };
enum class MemoryModel { ideal, latency };
enum class CacheReplacement { lru, fifo, random };
// Where a unit's cache misses go: its DRAM channel directly, over the shared bus to it, or
// out of the engine through its memory port (hw/engine.h `mem`) to a memory the platform
// binds there (the oprt command binds its own DRAM model, hw/dram.h: the figures of
// `channel`).
enum class DramPath { channel, bus, external };
enum class Level { at, lt, analytic };
// The intersection unit's microarchitecture: the paper's (one adder, one multiplier, one
// operation at a time) or a pipeline of a sphere unit, a transform unit and a triangle unit
// (timing/pipeline_timing.h, docs/cycle-model.md).
enum class IuModel { serial, pipelined };

// A pipelined IU's parameters (timing/pipeline_timing.h). Each unit's adders and
// multipliers: 0 = as many as its operation graph needs to accept a new operation every
// cycle (initiation interval 1).
struct IuConfig {
  IuModel model = IuModel::serial;
  int rays_in_flight = 16;  // rays between the ray FIFO and their answers, per IU
  // Each ray's traversal stack in the ray store (--accel bvh): entries, and what a spill or
  // a fill of one entry to object memory costs that ray.
  int stack_depth = 16;
  int stack_overflow_cycles = 10;
  int add_latency = 1, multiply_latency = 1;  // cycles, each FP unit itself pipelined
  struct Unit {
    int adders = 0, multipliers = 0;  // 0: enough for II 1
  } node, sphere, transform, box, triangle;  // node: --top bvh; box: --accel bvh
};

// The middle of the trade: --balance spatial's locality when none is given.
constexpr double kDefaultLocality = 0.5;

struct Arch {
  std::string source = "built-in defaults";
  double clock_mhz = 100;
  int ius = 32;
  CycleCosts costs;
  int fifo_depth = 0;  // rays per IU ray FIFO; 0 = unbounded
  struct {
    BusModel model = BusModel::ideal;
    int bytes_per_cycle = 8;
    int arbitration_cycles = 1;
    LtArbitration lt_arbitration = LtArbitration::sync;
  } bus;
  struct {
    MemoryModel model = MemoryModel::ideal;  // the on-chip object memory
    int latency_cycles = 10;
    int bytes_per_cycle = 16;
    // Capacity per unit; 0 = whatever its assignment needs. A unit whose spheres need more
    // uses it as a cache in front of DRAM (timing/cache.h).
    std::uint64_t sram_bytes = 0;
    struct {
      int line_bytes = 64;
      int ways = 4;
      CacheReplacement replacement = CacheReplacement::lru;
      int misses_outstanding = 4;  // per unit
    } cache;
    struct {
      int latency_cycles = 40;     // from the request to the line's first byte
      int bytes_per_cycle = 16;    // per channel
      int units_per_channel = 1;   // units 0..k-1 share channel 0, and so on (1: a channel per unit)
      DramPath path = DramPath::channel;
    } dram;
  } memory;
  struct {
    int cycles_per_ray = 0;  // generating a ray (primary or shadow)
    int cycles_per_hit = 0;  // shading a nearest hit (primary, reflection, refraction)
    int depth = -1;          // Whitted's recursion bound (Scene::depth); -1: the scene's
    int cycles_per_node = 20;  // --top bvh: refitting one node of a unit's tree, every frame
  } gpp;
  IuConfig iu;

  // Run options.
  Level level = Level::at;
  double quantum_ns = 1000;
  std::string balance = "paper";
  // Tight unit bounds (1) against balance (0) for `spatial` (unset: kDefaultLocality) and
  // `feedback` (unset: feedback on costs alone, as before locality existed).
  std::optional<double> locality;
  // Copies of hot spheres on several units (balance/replicate.h): 0 off, kReplicateAuto, or
  // at most that many copies of a sphere.
  int replicate = 0;
  static constexpr int kReplicateAuto = -1;
  int subdivide = 1;
  std::string split_rule = "balanced";  // how --subdivide splits an object (balance/subdivide.cpp)
  // How objects become spheres (balance/spheres.h): "count" or "extent"; "" is the scene
  // format's default, resolved when the scene is known (render records the resolved rule).
  std::string split;
  std::string accel = "brute";
  std::string top = "flat";  // what a unit walks over its spheres: "flat" (every one) or "bvh" (ref/top_tree.h)
  // Which units a ray goes to (ref/route.h): "broadcast" (every one, the paper's),
  // "multicast" (those whose bound it enters) or "ordered" (those, nearest first, in waves).
  struct {
    std::string policy = "broadcast";
    std::string transfer = "mask";  // a routed ray on the bus: one transfer with a unit mask, or "per_unit"
    int wave = 1;                   // ordered: units per wave
    IuConfig::Unit units;           // each of the router's box-test units: adders, multipliers (0: II 1)
    int lanes = 8;                  // box-test units side by side, each testing its share of the bounds
    std::string bound = "unit";     // what the router tests: a box per unit, or per visible sphere ("sphere")
  } route;
  Kernel kernel = Kernel::moller;
  std::string precision = "float";
  // Simulation only: make every unit wait out each ray in simulation time even where
  // nothing can observe the difference (local_clock.h, `ahead`). Tests use it to show that
  // skipping those waits changes no figure.
  bool sync_every_ray = false;

  double cycle_ns() const { return 1000.0 / clock_mhz; }
  // The costs of the kernel this run uses.
  const KernelCosts& kernel_costs() const { return costs.of(kernel); }
  bool top_tree() const { return top == "bvh"; }
  bool routed() const { return route.policy != "broadcast"; }
  // Whether the balance policy takes a locality (spatial, feedback).
  bool balance_takes_locality() const { return balance == "spatial" || balance == "feedback"; }
};

// Throws InputError (file, JSON path, problem) on any unknown key or impossible value.
// check_arch: combinations the model does not support (after command-line overrides);
// `origin` names a setting by where it came from ("--iu pipelined", "arch.json: /top bvh").
void check_arch(const Arch& a, const std::function<std::string(const std::string& key)>& origin = {});
Arch load_arch(const std::string& path);
// --replicate / "balance": {"replicate": ...}: "auto", "off" or a number of copies (1: off).
// Throws InputError naming `where`.
int replicate_named(const std::string& text, const std::string& where);
Arch arch_from_json(const nlohmann::json& doc, const std::string& file);
nlohmann::json to_json(const Arch& a);

// Throws InputError(file, place) if a limited object memory cannot hold one cache set.
void check_sram(const Arch& a, const std::string& file, const std::string& place);

// "10 ns", "1us", "100 us", "2.5 ms" -> nanoseconds (base/numbers.h parse_time_ps). Throws
// InputError naming `what`.
double parse_time_ns(const std::string& text, const std::string& what);

const char* to_string(Level l);
const char* to_string(BusModel b);
const char* to_string(LtArbitration b);
const char* to_string(MemoryModel m);
const char* to_string(CacheReplacement r);
const char* to_string(DramPath p);
const char* to_string(IuModel m);

}  // namespace oprt
