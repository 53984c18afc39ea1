#include "trace_select.h"

#include "base/error.h"
#include "base/numbers.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>

namespace oprt {

namespace {

// A scope component "iu12" as ("iu", 12); ("bus", -1) for one without a number.
std::pair<std::string, int> block_of(const std::string& part) {
  std::size_t d = part.size();
  while (d > 0 && std::isdigit(static_cast<unsigned char>(part[d - 1]))) --d;
  if (d == part.size() || d == 0 || part.size() - d > 6) return {part, -1};
  return {part.substr(0, d), std::stoi(part.substr(d))};
}

// The signal groups, one row each: which signals belong to it, by the innermost block of
// the signal's scope (its number stripped: "iu", "fifo", "bus", "gpp") and the signal's name.
struct GroupRule {
  const char* group;
  bool (*claims)(const std::string& block, const std::string& name);
};
const GroupRule kGroups[] = {
    {"state", [](const std::string& b, const std::string& n) { return b == "iu" && n == "state"; }},
    {"fifo", [](const std::string& b, const std::string&) { return b == "fifo"; }},
    {"bus", [](const std::string& b, const std::string&) { return b == "bus"; }},
    {"gpp", [](const std::string& b, const std::string&) { return b == "gpp"; }},
    {"memory", [](const std::string& b, const std::string&) { return b == "memory"; }},  // --sram: misses
    {"stage", [](const std::string& b, const std::string&) { return b == "stage"; }},    // --iu pipelined
};
// Blocks that belong to one intersection unit (their number is the unit's).
bool per_unit(const std::string& block) { return block == "iu" || block == "fifo" || block == "memory"; }

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// A unit number as --trace-units takes it (the architecture allows 65536 units).
int unit_number(const std::string& s, const std::string& text) {
  return static_cast<int>(parse_count(s, 0, 65535, {"--trace-units", text}));
}

std::string list(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

}  // namespace

SignalKind classify_signal(const std::string& scope, const std::string& name) {
  SignalKind k;
  std::string innermost;
  std::size_t b = 0;
  for (;;) {
    const std::size_t e = scope.find('.', b);
    const auto [block, number] = block_of(scope.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (number >= 0 && per_unit(block) && k.unit < 0) k.unit = number;
    innermost = block;
    if (e == std::string::npos) break;
    b = e + 1;
  }
  for (const GroupRule& r : kGroups)
    if (r.claims(innermost, name)) {
      k.group = r.group;
      break;
    }
  return k;
}

std::vector<std::string> signal_groups() {
  std::vector<std::string> g;
  for (const GroupRule& r : kGroups) g.push_back(r.group);
  return g;
}

bool TraceSelection::traces(const std::string& scope, const std::string& group) const {
  if (!groups.empty() && std::find(groups.begin(), groups.end(), group) == groups.end()) return false;
  if (units.empty()) return true;
  const int unit = classify_signal(scope, "").unit;
  return unit < 0 || std::binary_search(units.begin(), units.end(), unit);
}

bool TraceSelection::traces_signal(const std::string& scope, const std::string& name) const {
  return traces(scope, classify_signal(scope, name).group);
}

FrameRange parse_trace_frames(const std::string& text, const FrameRange& rendered) {
  const FrameRange r = parse_frame_range(text, "--trace-frames");
  if (r.first < rendered.first || r.last > rendered.last)
    throw InputError("--trace-frames", text,
                     "the run renders frames " + std::to_string(rendered.first) + ":" + std::to_string(rendered.last) +
                         " only (--frames)");
  return r;
}

void parse_trace_window(const std::string& text, std::uint64_t& from_ps, std::uint64_t& to_ps) {
  const auto colon = text.find(':');
  if (colon == std::string::npos || text.find(':', colon + 1) != std::string::npos)
    throw InputError("--trace-window", text, "expected T0:T1 such as 10us:2ms (either side may be empty)");
  const std::string a = trim(text.substr(0, colon)), b = trim(text.substr(colon + 1));
  from_ps = a.empty() ? 0 : parse_time_ps(a, true, {"--trace-window", a});
  to_ps = b.empty() ? TraceSelection::kNever : parse_time_ps(b, true, {"--trace-window", b});
  if (from_ps >= to_ps) throw InputError("--trace-window", text, "the window must end after it starts");
}

std::vector<int> parse_trace_units(const std::string& text) {
  std::vector<int> units;
  const std::string expected = "expected units and ranges such as 0-3,7";
  std::size_t b = 0;
  for (;;) {
    const std::size_t e = text.find(',', b);
    const std::string item = trim(text.substr(b, e == std::string::npos ? std::string::npos : e - b));
    const auto dash = item.find('-');
    if (item.empty() || item.find_first_not_of("0123456789- \t") != std::string::npos || dash == 0 ||
        dash == item.size() - 1 || (dash != std::string::npos && item.find('-', dash + 1) != std::string::npos))
      throw InputError("--trace-units", text, expected);
    const int lo = unit_number(dash == std::string::npos ? item : trim(item.substr(0, dash)), text);
    const int hi = dash == std::string::npos ? lo : unit_number(trim(item.substr(dash + 1)), text);
    if (lo > hi) throw InputError("--trace-units", text, "range " + item + " ends before it starts");
    for (int u = lo; u <= hi; ++u) units.push_back(u);
    if (e == std::string::npos) break;
    b = e + 1;
  }
  std::sort(units.begin(), units.end());
  units.erase(std::unique(units.begin(), units.end()), units.end());
  return units;
}

void check_trace_units(const std::string& text, const std::vector<int>& units, std::size_t unit_count) {
  for (int u : units)
    if (static_cast<std::size_t>(u) >= unit_count)
      throw InputError("--trace-units", text,
                       "unit " + std::to_string(u) + " does not exist: this run has " + std::to_string(unit_count) +
                           " units (0-" + std::to_string(unit_count - 1) + ")");
}

std::vector<std::string> parse_trace_signals(const std::string& text) {
  const std::vector<std::string> known = signal_groups();
  std::vector<std::string> groups;
  std::size_t b = 0;
  for (;;) {
    const std::size_t e = text.find(',', b);
    const std::string g = trim(text.substr(b, e == std::string::npos ? std::string::npos : e - b));
    if (std::find(known.begin(), known.end(), g) == known.end())
      throw InputError("--trace-signals", text,
                       (g.empty() ? std::string("empty signal group") : "unknown signal group \"" + g + "\"") +
                           " (expected a list of: " + list(known) + ")");
    if (std::find(groups.begin(), groups.end(), g) == groups.end()) groups.push_back(g);
    if (e == std::string::npos) break;
    b = e + 1;
  }
  return groups;
}

}  // namespace oprt
