#include "base/json_in.h"

#include "base/numbers.h"
#include "base/read_file.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

namespace oprt {

namespace {
std::string escape_pointer(const std::string& key) {
  std::string out;
  for (char c : key) {
    if (c == '~') out += "~0";
    else if (c == '/') out += "~1";
    else out += c;
  }
  return out;
}

std::string describe(double x) {
  if (std::isnan(x)) return "NaN";
  if (std::isinf(x)) return x > 0 ? "infinity" : "-infinity";
  std::ostringstream s;
  s << x;
  return s.str();
}
}  // namespace

namespace {
// A byte offset (0-based) as "line L, column C".
std::string line_column(const std::string& text, std::size_t byte) {
  std::size_t line = 1, col = 1;
  const std::size_t end = std::min(byte, text.size());
  for (std::size_t i = 0; i < end; ++i) {
    if (text[i] == '\n') ++line, col = 1;
    else ++col;
  }
  return "line " + std::to_string(line) + ", column " + std::to_string(col);
}

// Finds where a document fails (nlohmann reports a number too large for a double, 1e999, as
// out_of_range without a position; its SAX interface has the position).
struct ErrorPosition final : nlohmann::json_sax<nlohmann::json> {
  std::size_t byte = 0;
  bool null() override { return true; }
  bool boolean(bool) override { return true; }
  bool number_integer(number_integer_t) override { return true; }
  bool number_unsigned(number_unsigned_t) override { return true; }
  bool number_float(number_float_t, const string_t&) override { return true; }
  bool string(string_t&) override { return true; }
  bool binary(binary_t&) override { return true; }
  bool start_object(std::size_t) override { return true; }
  bool key(string_t&) override { return true; }
  bool end_object() override { return true; }
  bool start_array(std::size_t) override { return true; }
  bool end_array() override { return true; }
  bool parse_error(std::size_t position, const std::string&, const nlohmann::detail::exception&) override {
    byte = position;
    return false;
  }
};
}  // namespace

nlohmann::json JsonIn::parse_text(const std::string& text, const std::string& file) {
  try {
    // Comments are not JSON; NaN and Infinity are not JSON either, and the parser rejects them.
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::parse_error& e) {
    // e.byte is 1-based.
    std::string what = e.what();
    const auto colon = what.find("parse error");
    if (colon != std::string::npos) what = what.substr(colon);
    throw InputError(file, line_column(text, e.byte ? e.byte - 1 : 0), "malformed JSON: " + what);
  } catch (const nlohmann::json::out_of_range& e) {
    // A number beyond the range of a double, such as 1e999 (the only way to write infinity).
    ErrorPosition where;
    nlohmann::json::sax_parse(text, &where);
    std::string what = e.what();
    const auto bracket = what.find("] ");
    if (bracket != std::string::npos) what = what.substr(bracket + 2);
    throw InputError(file, line_column(text, where.byte ? where.byte - 1 : 0),
                     "malformed JSON: " + what + " (numbers must be finite)");
  }
}

nlohmann::json JsonIn::parse_file(const std::string& file) { return parse_text(read_file_text(file), file); }

void JsonIn::fail(const std::string& problem) const { throw InputError(file_, place(), problem); }

std::string JsonIn::type_name() const { return j_->type_name(); }

JsonIn JsonIn::at(const std::string& key) const {
  if (!j_->is_object()) fail("expected an object, found " + type_name());
  auto it = j_->find(key);
  if (it == j_->end()) fail("missing required key \"" + key + "\"");
  return JsonIn(*it, file_, path_ + "/" + escape_pointer(key));
}

std::optional<JsonIn> JsonIn::find(const std::string& key) const {
  if (!j_->is_object()) fail("expected an object, found " + type_name());
  auto it = j_->find(key);
  if (it == j_->end()) return std::nullopt;
  return JsonIn(*it, file_, path_ + "/" + escape_pointer(key));
}

void JsonIn::only_keys(std::initializer_list<const char*> allowed) const {
  if (!j_->is_object()) fail("expected an object, found " + type_name());
  for (auto it = j_->begin(); it != j_->end(); ++it) {
    bool ok = false;
    for (const char* a : allowed) ok = ok || it.key() == a;
    if (!ok) {
      std::string list;
      for (const char* a : allowed) list += std::string(list.empty() ? "" : ", ") + a;
      JsonIn(*it, file_, path_ + "/" + escape_pointer(it.key()))
          .fail("unknown key \"" + it.key() + "\" (expected one of: " + list + ")");
    }
  }
}

std::vector<JsonIn> JsonIn::items() const {
  if (!j_->is_array()) fail("expected an array, found " + type_name());
  std::vector<JsonIn> out;
  out.reserve(j_->size());
  for (std::size_t i = 0; i < j_->size(); ++i)
    out.emplace_back((*j_)[i], file_, path_ + "/" + std::to_string(i));
  return out;
}

std::vector<std::pair<std::string, JsonIn>> JsonIn::members() const {
  if (!j_->is_object()) fail("expected an object, found " + type_name());
  std::vector<std::pair<std::string, JsonIn>> out;
  for (auto it = j_->begin(); it != j_->end(); ++it)
    out.emplace_back(it.key(), JsonIn(*it, file_, path_ + "/" + escape_pointer(it.key())));
  return out;
}

double JsonIn::number() const {
  if (!j_->is_number()) fail("expected a number, found " + type_name());
  const double x = j_->get<double>();
  if (!std::isfinite(x)) fail("expected a finite number, found " + describe(x));
  return x;
}

double JsonIn::number(double lo, double hi) const {
  const double x = number();
  if (x < lo || x > hi)
    fail("value " + describe(x) + " is out of range [" + describe(lo) + ", " + describe(hi) + "]");
  return x;
}

long long JsonIn::integer(long long lo, long long hi) const {
  const auto out_of_range = [&](const std::string& value) {
    fail("value " + value + " is out of range [" + std::to_string(lo) + ", " + std::to_string(hi) + "]");
  };
  if (j_->is_number_float()) {
    const double x = j_->get<double>();
    // A whole number written as a float (4096.0, 1e20): in range or out of it, like an integer.
    if (!std::isfinite(x) || x != std::floor(x)) fail("expected an integer, found " + describe(x));
    if (x < static_cast<double>(lo) || x > static_cast<double>(hi) || std::fabs(x) >= 9.2e18) out_of_range(describe(x));
    return static_cast<long long>(x);
  }
  if (!j_->is_number_integer()) fail("expected an integer, found " + type_name());
  if (j_->is_number_unsigned()) {
    const auto u = j_->get<unsigned long long>();
    if (u > static_cast<unsigned long long>(hi) || (lo > 0 && u < static_cast<unsigned long long>(lo)))
      out_of_range(std::to_string(u));
    return static_cast<long long>(u);
  }
  const long long v = j_->get<long long>();
  if (v < lo || v > hi) out_of_range(std::to_string(v));
  return v;
}

std::uint64_t JsonIn::bytes(std::uint64_t hi) const {
  if (j_->is_string()) return parse_bytes(j_->get<std::string>(), hi, {file_, place()});
  if (!j_->is_number()) fail("expected a byte count (an integer, or a string such as \"64K\"), found " + type_name());
  if (j_->is_number_unsigned()) {
    const auto u = j_->get<unsigned long long>();
    if (u > hi) parse_bytes(std::to_string(u), hi, {file_, place()});  // states the limit
    return u;
  }
  return static_cast<std::uint64_t>(integer(0, static_cast<long long>(std::min<std::uint64_t>(hi, 1ULL << 62))));
}

bool JsonIn::boolean() const {
  if (!j_->is_boolean()) fail("expected true or false, found " + type_name());
  return j_->get<bool>();
}

std::string JsonIn::string() const {
  if (!j_->is_string()) fail("expected a string, found " + type_name());
  return j_->get<std::string>();
}

std::array<double, 3> JsonIn::array3() const {
  if (!j_->is_array() || j_->size() != 3)
    fail("expected an array of 3 numbers, found " +
         (j_->is_array() ? "an array of " + std::to_string(j_->size()) : type_name()));
  auto it = items();
  return {it[0].number(), it[1].number(), it[2].number()};
}

double JsonIn::number_or(const std::string& key, double def, double lo, double hi) const {
  auto v = find(key);
  return v ? v->number(lo, hi) : def;
}
long long JsonIn::integer_or(const std::string& key, long long def, long long lo, long long hi) const {
  auto v = find(key);
  return v ? v->integer(lo, hi) : def;
}
std::uint64_t JsonIn::bytes_or(const std::string& key, std::uint64_t def, std::uint64_t hi) const {
  auto v = find(key);
  return v ? v->bytes(hi) : def;
}
bool JsonIn::boolean_or(const std::string& key, bool def) const {
  auto v = find(key);
  return v ? v->boolean() : def;
}
std::string JsonIn::string_or(const std::string& key, const std::string& def) const {
  auto v = find(key);
  return v ? v->string() : def;
}

}  // namespace oprt
