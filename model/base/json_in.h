// Strict reading of a JSON document: every value knows its path (/objects/3/mesh), every
// object declares the keys it accepts, and every problem becomes an InputError naming the
// file and the path. Used for scene files, architecture files and sweep specs.
#pragma once

#include "base/error.h"

#include <array>
#include <cstdint>
#include <initializer_list>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace oprt {

class JsonIn {
 public:
  JsonIn(const nlohmann::json& j, std::string file, std::string path = "")
      : j_(&j), file_(std::move(file)), path_(std::move(path)) {}

  // Parse a whole file; a syntax error names the line and column.
  static nlohmann::json parse_file(const std::string& file);
  static nlohmann::json parse_text(const std::string& text, const std::string& file);

  const nlohmann::json& raw() const { return *j_; }
  const std::string& file() const { return file_; }
  std::string place() const { return path_.empty() ? "/" : path_; }

  bool is_object() const { return j_->is_object(); }
  bool is_array() const { return j_->is_array(); }
  bool is_string() const { return j_->is_string(); }
  bool is_number() const { return j_->is_number(); }

  JsonIn at(const std::string& key) const;                // required member
  std::optional<JsonIn> find(const std::string& key) const;
  bool has(const std::string& key) const { return find(key).has_value(); }
  void only_keys(std::initializer_list<const char*> allowed) const;
  std::vector<JsonIn> items() const;                       // array elements
  std::vector<std::pair<std::string, JsonIn>> members() const;

  double number() const;  // finite
  double number(double lo, double hi) const;  // finite, in [lo, hi]
  long long integer(long long lo, long long hi) const;
  // A byte count: an integer, or a string with a suffix ("64K", "1.5 GiB"; base/numbers.h).
  std::uint64_t bytes(std::uint64_t hi) const;
  bool boolean() const;
  std::string string() const;
  std::array<double, 3> array3() const;  // three numbers (scene/json_vec.h reads them as a vector)

  // Optional members with a default.
  double number_or(const std::string& key, double def, double lo = -1e300, double hi = 1e300) const;
  long long integer_or(const std::string& key, long long def, long long lo, long long hi) const;
  std::uint64_t bytes_or(const std::string& key, std::uint64_t def, std::uint64_t hi) const;
  bool boolean_or(const std::string& key, bool def) const;
  std::string string_or(const std::string& key, const std::string& def) const;

  [[noreturn]] void fail(const std::string& problem) const;

 private:
  std::string type_name() const;
  const nlohmann::json* j_;
  std::string file_, path_;
};

}  // namespace oprt
