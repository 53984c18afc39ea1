#include "base/numbers.h"

#include "base/error.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <cstring>

namespace oprt {

namespace {

constexpr std::uint64_t kMax = ~std::uint64_t{0};

bool mul(std::uint64_t a, std::uint64_t b, std::uint64_t& out) {
  if (a != 0 && b > kMax / a) return false;
  out = a * b;
  return true;
}

std::uint64_t pow10(int n) {  // n <= 19
  std::uint64_t p = 1;
  while (n-- > 0) p *= 10;
  return p;
}

std::string trim(const std::string& s) {
  const auto b = s.find_first_not_of(" \t");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t") - b + 1);
}

// A decimal number as written: digits, an optional fraction and (if allowed) an exponent,
// as an integer mantissa and a power of ten, exactly. `rest` is what follows it. False if
// the text does not start with a number. A mantissa beyond 64 bits sets `overflow`.
struct Decimal {
  std::uint64_t mantissa = 0;
  long exponent = 0;
  bool overflow = false;
  std::string rest;
};

bool read_decimal(const std::string& t, bool allow_exponent, Decimal& d) {
  std::size_t i = 0, digits = 0;
  auto take = [&](bool fraction) {
    for (; i < t.size() && std::isdigit(static_cast<unsigned char>(t[i])); ++i, ++digits) {
      const unsigned v = static_cast<unsigned>(t[i] - '0');
      if (d.overflow || d.mantissa > (kMax - v) / 10) {
        // Beyond 64 bits: a zero after the point changes nothing; otherwise keep the scale.
        if (!fraction) ++d.exponent;
        if (v != 0) d.overflow = true;
        continue;
      }
      d.mantissa = d.mantissa * 10 + v;
      if (fraction) --d.exponent;
    }
  };
  take(false);
  if (i < t.size() && t[i] == '.') {
    ++i;
    take(true);
  }
  if (digits == 0) return false;
  if (allow_exponent && i < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    std::size_t j = i + 1;
    const bool negative = j < t.size() && t[j] == '-';
    if (j < t.size() && (t[j] == '-' || t[j] == '+')) ++j;
    if (j < t.size() && std::isdigit(static_cast<unsigned char>(t[j]))) {
      long e = 0;
      for (; j < t.size() && std::isdigit(static_cast<unsigned char>(t[j])); ++j) e = std::min(e * 10 + (t[j] - '0'), 100000L);
      d.exponent += negative ? -e : e;
      i = j;
    }
  }
  // Trailing zeros of the mantissa into the exponent: 1.50 is 15 x 10^-1.
  while (d.mantissa != 0 && d.mantissa % 10 == 0) d.mantissa /= 10, ++d.exponent;
  if (d.mantissa == 0) d.exponent = 0;
  d.rest = trim(t.substr(i));
  return true;
}

enum class Scaled { ok, too_large, fraction };

// mantissa x 10^exponent x factor, exactly, as an integer.
Scaled scale(const Decimal& d, std::uint64_t factor, std::uint64_t& out) {
  if (d.overflow) return Scaled::too_large;
  if (d.mantissa == 0) return out = 0, Scaled::ok;
  std::uint64_t v;
  if (d.exponent >= 0) {
    if (d.exponent > 19 || !mul(d.mantissa, pow10(static_cast<int>(d.exponent)), v) || !mul(v, factor, v))
      return Scaled::too_large;
    return out = v, Scaled::ok;
  }
  // Divide by 10^-exponent: the product must stay whole. Mantissa has no factor of 10 left,
  // so the division is exact only if the factor supplies the missing powers of 2 and 5.
  if (-d.exponent > 19) return Scaled::fraction;
  const std::uint64_t p = pow10(static_cast<int>(-d.exponent));
  if (!mul(d.mantissa, factor, v)) {
    // Too large for 64 bits before the division: divide the factor first where it can be.
    if (factor % p != 0 || !mul(d.mantissa, factor / p, v)) return Scaled::too_large;
    return out = v, Scaled::ok;
  }
  if (v % p != 0) return Scaled::fraction;
  return out = v / p, Scaled::ok;
}

[[noreturn]] void refuse(const NumberSource& at, const std::string& problem) {
  throw InputError(at.file, at.place, problem);
}

std::string range(std::uint64_t lo, std::uint64_t hi) {
  return "[" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
}

}  // namespace

std::uint64_t parse_count(const std::string& text, std::uint64_t lo, std::uint64_t hi, const NumberSource& at) {
  const std::string t = trim(text);
  bool digits = !t.empty();
  for (char c : t) digits = digits && std::isdigit(static_cast<unsigned char>(c));
  if (!digits) refuse(at, "expected a whole number in " + range(lo, hi));
  Decimal d;
  read_decimal(t, false, d);
  std::uint64_t v = 0;
  if (scale(d, 1, v) != Scaled::ok || v > hi || v < lo)
    refuse(at, "value " + t + " is out of range " + range(lo, hi));
  return v;
}

std::uint64_t parse_bytes(const std::string& text, std::uint64_t hi, const NumberSource& at) {
  const std::string limit = "at most " + byte_count_text(hi) +
                            (hi >= 1024 ? " (" + std::to_string(hi) + " bytes)" : "");
  const std::string expected = "expected a byte count such as 65536, 64K, 4M or 1.5G (K, M, G, T: powers of 1024, "
                               "also written KB or KiB), " + limit;
  Decimal d;
  if (!read_decimal(trim(text), false, d)) refuse(at, expected);
  std::string unit = d.rest;
  std::uint64_t factor = 1;
  if (!unit.empty()) {
    const char* const prefixes = "KMGT";
    const char p = static_cast<char>(std::toupper(static_cast<unsigned char>(unit[0])));
    const char* k = p ? std::strchr(prefixes, p) : nullptr;
    const std::string tail = unit.substr(1);
    if (!k || !(tail.empty() || tail == "B" || tail == "iB")) refuse(at, expected);
    for (const char* q = prefixes; q <= k; ++q) factor *= 1024;
  }
  std::uint64_t v = 0;
  switch (scale(d, factor, v)) {
    case Scaled::too_large: refuse(at, "value " + trim(text) + " is more than the limit: " + limit);
    case Scaled::fraction: refuse(at, "value " + trim(text) + " is not a whole number of bytes");
    case Scaled::ok: break;
  }
  if (v > hi) refuse(at, "value " + trim(text) + " (" + std::to_string(v) + " bytes) is more than the limit: " + limit);
  return v;
}

std::uint64_t parse_time_ps(const std::string& text, bool zero_ok, const NumberSource& at) {
  const std::string t = trim(text);
  const std::string expected = "expected a time such as 10us or 2.5 ms (units ps, ns, us, ms, s)";
  Decimal d;
  if (t.empty() || !read_decimal(t, true, d)) refuse(at, expected);
  static const std::pair<const char*, std::uint64_t> kUnits[] = {
      {"ps", 1}, {"ns", 1000}, {"us", 1000000}, {"ms", 1000000000}, {"s", 1000000000000}};
  std::uint64_t factor = 0;
  for (const auto& [name, f] : kUnits)
    if (d.rest == name) factor = f;
  if (factor == 0) {
    if (!d.rest.empty()) refuse(at, "unknown time unit \"" + d.rest + "\" (expected ps, ns, us, ms or s)");
    if (d.mantissa != 0) refuse(at, "a time needs a unit (ps, ns, us, ms, s)");
    factor = 1;
  }
  std::uint64_t ps = 0;
  switch (scale(d, factor, ps)) {
    case Scaled::too_large:
      refuse(at, "value " + t + " is more than 2^64 - 1 ps (18446744.073709551615 s, about 213 days), the longest "
                 "time SystemC can hold");
    case Scaled::fraction: refuse(at, "value " + t + " is not a whole number of picoseconds (SystemC's resolution)");
    case Scaled::ok: break;
  }
  if (ps == 0 && !zero_ok) refuse(at, "value " + t + " must be positive");
  return ps;
}

std::string byte_count_text(std::uint64_t bytes) {
  static const char* const kUnits[] = {"KiB", "MiB", "GiB", "TiB", "PiB", "EiB"};
  if (bytes < 1024) return std::to_string(bytes) + (bytes == 1 ? " byte" : " bytes");
  int k = 0;
  std::uint64_t scale = 1024;
  while (k < 5 && bytes / scale >= 1024) scale *= 1024, ++k;
  if (bytes % scale == 0) return std::to_string(bytes / scale) + " " + kUnits[k];
  char s[32];
  std::snprintf(s, sizeof s, "%.1f %s", static_cast<double>(bytes) / static_cast<double>(scale), kUnits[k]);
  return s;
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

}  // namespace oprt
