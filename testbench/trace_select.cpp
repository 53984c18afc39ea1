#include "trace_select.h"

#include "scene/error.h"

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

bool parse_count(const std::string& s, long long& out) {
  if (s.empty() || s.size() > 9) return false;
  for (char c : s)
    if (!std::isdigit(static_cast<unsigned char>(c))) return false;
  out = std::stoll(s);
  return true;
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
  const auto colon = text.find(':');
  long long a, b;
  const bool ok = colon == std::string::npos
                      ? parse_count(text, a) && (b = a, true)
                      : parse_count(text.substr(0, colon), a) && parse_count(text.substr(colon + 1), b);
  if (!ok) throw InputError("--trace-frames", text, "expected N or A:B (frame numbers, inclusive)");
  if (a > b) throw InputError("--trace-frames", text, "first frame is after the last");
  if (a < rendered.first || b > rendered.last)
    throw InputError("--trace-frames", text,
                     "the run renders frames " + std::to_string(rendered.first) + ":" + std::to_string(rendered.last) +
                         " only (--frames)");
  return {static_cast<int>(a), static_cast<int>(b)};
}

std::uint64_t parse_time_ps(const std::string& text, const std::string& option) {
  const std::string t = trim(text);
  const char* s = t.c_str();
  char* end = nullptr;
  const double v = std::strtod(s, &end);
  const std::string expected = "expected a time such as 10us or 2ms (ps, ns, us, ms, s)";
  if (end == s || t[0] == '-' || t[0] == '+' || !std::isfinite(v)) throw InputError(option, text, expected);
  const std::string unit = trim(end);
  double scale;
  if (unit == "ps") scale = 1;
  else if (unit == "ns") scale = 1e3;
  else if (unit == "us") scale = 1e6;
  else if (unit == "ms") scale = 1e9;
  else if (unit == "s") scale = 1e12;
  else if (unit.empty() && v == 0) scale = 1;
  else if (unit.empty()) throw InputError(option, text, "a time needs a unit (ps, ns, us, ms, s)");
  else throw InputError(option, text, "unknown time unit \"" + unit + "\" (expected ps, ns, us, ms or s)");
  const double ps = v * scale;
  if (ps >= 1.8e19) throw InputError(option, text, "time too large");
  return static_cast<std::uint64_t>(std::llround(ps));
}

std::string format_time_ps(std::uint64_t ps) {
  static const std::pair<std::uint64_t, const char*> kUnits[] = {
      {1000000000000ULL, "s"}, {1000000000ULL, "ms"}, {1000000ULL, "us"}, {1000ULL, "ns"}};
  for (const auto& [scale, name] : kUnits)
    if (ps >= scale) {
      std::string s = std::to_string(ps / scale);
      if (std::uint64_t frac = ps % scale) {
        std::string f = std::to_string(frac + scale).substr(1);  // leading zeros kept
        f.erase(f.find_last_not_of('0') + 1);
        s += "." + f;
      }
      return s + name;
    }
  return std::to_string(ps) + "ps";
}

void parse_trace_window(const std::string& text, std::uint64_t& from_ps, std::uint64_t& to_ps) {
  const auto colon = text.find(':');
  if (colon == std::string::npos || text.find(':', colon + 1) != std::string::npos)
    throw InputError("--trace-window", text, "expected T0:T1 such as 10us:2ms (either side may be empty)");
  const std::string a = trim(text.substr(0, colon)), b = trim(text.substr(colon + 1));
  from_ps = a.empty() ? 0 : parse_time_ps(a, "--trace-window");
  to_ps = b.empty() ? TraceSelection::kNever : parse_time_ps(b, "--trace-window");
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
    long long lo, hi;
    const bool ok = dash == std::string::npos
                        ? parse_count(item, lo) && (hi = lo, true)
                        : parse_count(trim(item.substr(0, dash)), lo) && parse_count(trim(item.substr(dash + 1)), hi);
    if (!ok) throw InputError("--trace-units", text, expected);
    if (lo > hi) throw InputError("--trace-units", text, "range " + item + " ends before it starts");
    if (hi - lo > 1 << 20) throw InputError("--trace-units", text, "range " + item + " is too long");
    for (long long u = lo; u <= hi; ++u) units.push_back(static_cast<int>(u));
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
