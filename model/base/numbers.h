// The numbers users write, one parser for each kind: counts, byte counts and times. The
// command line, the scene, architecture and technology files and the sweep specs (through
// `oprt check-number`, scripts/sweep) all read them here, so that "64K" or "1.5ms" means the
// same everywhere, and every refusal states the real limit. A refusal is an InputError
// naming the file (or the option) and the place; the caller says which.
#pragma once

#include <cstdint>
#include <string>

namespace oprt {

// Where a number was written: a file and a place in it ("arch.json", "/memory/sram_bytes"),
// or an option and its value ("--sram", "2T").
struct NumberSource {
  std::string file, place;
};

// A count: decimal digits only ("4096"; no sign, suffix or exponent), in [lo, hi].
std::uint64_t parse_count(const std::string& text, std::uint64_t lo, std::uint64_t hi, const NumberSource& at);

// A byte count: a whole or decimal number, optionally followed by a binary multiple: K, M,
// G, T (powers of 1024), also written KB, MB, ... and KiB, MiB, ... ("65536", "64K",
// "64 KiB", "1.5G"); at most `hi` bytes, and a whole number of bytes.
std::uint64_t parse_bytes(const std::string& text, std::uint64_t hi, const NumberSource& at);

// A time with its unit (ps, ns, us, ms, s; "10 ns", "1.5ms", "2e3 us"), as picoseconds
// (SystemC's resolution: finer digits are refused). At most 2^64 - 1 ps (about 213 days),
// the largest time SystemC can hold. "0" needs no unit; zero is refused unless `zero_ok`.
std::uint64_t parse_time_ps(const std::string& text, bool zero_ok, const NumberSource& at);

// Byte counts and picoseconds for messages: "1 TiB", "4.5 GiB", "65536 bytes"; "1.5ms".
std::string byte_count_text(std::uint64_t bytes);
std::string format_time_ps(std::uint64_t ps);

// Limits stated once for everything that uses them.
constexpr std::uint64_t kMaxSramBytes = std::uint64_t{1} << 40;  // memory.sram_bytes, --sram: 1 TiB
constexpr std::uint64_t kMaxTimePs = ~std::uint64_t{0};          // SystemC's sc_time: 2^64 - 1 ps

}  // namespace oprt
