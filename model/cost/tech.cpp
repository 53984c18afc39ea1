#include "cost/tech.h"

#include "base/json_in.h"

#include <cmath>
#include <set>
#include <sstream>
#include <stdexcept>

namespace oprt {

SizeCurve::SizeCurve(std::vector<Point> points) : points_(std::move(points)) {
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (!(points_[i].bytes > 0) || !(points_[i].value > 0)) throw std::invalid_argument("SizeCurve: values must be positive");
    if (i && !(points_[i].bytes > points_[i - 1].bytes))
      throw std::invalid_argument("SizeCurve: capacities must increase");
  }
}

SizeCurve::Lookup SizeCurve::at(double bytes) const {
  if (points_.empty()) throw std::logic_error("SizeCurve::at on an empty curve");
  const auto power_law = [](const Point& a, const Point& b, double x) {
    const double t = std::log(x / a.bytes) / std::log(b.bytes / a.bytes);
    return std::exp(std::log(a.value) + t * std::log(b.value / a.value));
  };
  if (bytes < points_.front().bytes) return {points_.front().value, Range::below};
  for (std::size_t i = 0; i < points_.size(); ++i) {
    if (bytes == points_[i].bytes) return {points_[i].value, Range::point};
    if (i + 1 < points_.size() && bytes < points_[i + 1].bytes)
      return {power_law(points_[i], points_[i + 1], bytes), Range::interpolated};
  }
  if (points_.size() == 1) return {points_.front().value, Range::above};
  const std::size_t n = points_.size();
  return {power_law(points_[n - 2], points_[n - 1], bytes), Range::above};
}

namespace {

constexpr double kMinValue = 1e-30, kMaxValue = 1e30;

// The kinds of quantity a table holds, and the units each may be written in (scale to
// the unit Tech stores).
enum class Kind { area, energy, bytes, wire, power_density, length };

struct UnitName {
  const char* name;
  double scale;
};

const std::vector<UnitName>& units_of(Kind k) {
  static const std::vector<UnitName> area{{"mm2", 1}, {"um2", 1e-6}};
  static const std::vector<UnitName> energy{{"pJ", 1}, {"fJ", 1e-3}, {"nJ", 1e3}};
  static const std::vector<UnitName> bytes{
      {"bytes", 1}, {"KiB", 1024}, {"MiB", 1024.0 * 1024}, {"GiB", 1024.0 * 1024 * 1024}, {"TiB", 1024.0 * 1024 * 1024 * 1024}};
  static const std::vector<UnitName> wire{{"pJ/bit/mm", 1}, {"fJ/bit/mm", 1e-3}};
  static const std::vector<UnitName> power{{"W/mm2", 1}, {"mW/mm2", 1e-3}};
  static const std::vector<UnitName> length{{"nm", 1}};
  switch (k) {
    case Kind::area: return area;
    case Kind::energy: return energy;
    case Kind::bytes: return bytes;
    case Kind::wire: return wire;
    case Kind::power_density: return power;
    case Kind::length: return length;
  }
  throw std::logic_error("units_of");
}

const char* kind_name(Kind k) {
  switch (k) {
    case Kind::area: return "an area";
    case Kind::energy: return "an energy";
    case Kind::bytes: return "a size";
    case Kind::wire: return "an energy per bit and mm";
    case Kind::power_density: return "a power per area";
    case Kind::length: return "a feature size";
  }
  return "?";
}

class Reader {
 public:
  explicit Reader(std::set<std::string> sources) : sources_(std::move(sources)) {}

  // {"value", "unit", "source", "basis", "note"}: a positive number, in a unit of kind k,
  // from a listed source; "derived" and "unconfirmed" say how, in the note.
  double entry(const JsonIn& j, Kind k) const {
    j.only_keys({"value", "unit", "source", "basis", "note"});
    const JsonIn v = j.at("value");
    const double value = v.number();
    if (!(value > 0)) {
      std::ostringstream s;
      s << "must be positive, found " << value;
      v.fail(s.str());
    }
    const JsonIn u = j.at("unit");
    const std::string unit = u.string();
    double scale = 0;
    std::string list;
    for (const UnitName& n : units_of(k)) {
      if (unit == n.name) scale = n.scale;
      list += std::string(list.empty() ? "" : ", ") + n.name;
    }
    if (scale == 0) u.fail("unit \"" + unit + "\" is not " + kind_name(k) + " (expected one of: " + list + ")");
    // One range for every value, in the unit it is kept in: wide enough for any technology,
    // narrow enough that a value times a run's counts (below 2^64) stays a finite double.
    const double kept = value * scale;
    if (!(kept >= kMinValue && kept <= kMaxValue)) {
      std::ostringstream s;
      s << "value " << value << " " << unit << " is " << kept << " " << units_of(k).front().name
        << ", outside the range a table may hold, [" << kMinValue << ", " << kMaxValue << "] "
        << units_of(k).front().name;
      v.fail(s.str());
    }
    const JsonIn src = j.at("source");
    const std::string source = src.string();
    if (!sources_.count(source)) src.fail("unknown source \"" + source + "\" (list it under /sources)");
    const JsonIn b = j.at("basis");
    const std::string basis = b.string();
    if (basis != "quoted" && basis != "derived" && basis != "unconfirmed")
      b.fail("unknown basis \"" + basis + "\" (expected one of: quoted, derived, unconfirmed)");
    const auto note = j.find("note");
    if (note && note->string().empty()) note->fail("empty note");
    if (basis != "quoted" && !note) j.fail("a " + basis + " value needs a \"note\" saying how it was obtained");
    return kept;
  }

  std::optional<double> optional(const JsonIn& parent, const char* key, Kind k) const {
    if (auto j = parent.find(key)) return entry(*j, k);
    return std::nullopt;
  }

  // [{"capacity": entry, <value_key>: entry}, ...], capacities increasing.
  SizeCurve curve(const JsonIn& j, const char* value_key, Kind k) const {
    std::vector<SizeCurve::Point> points;
    const auto items = j.items();
    if (items.empty()) j.fail("expected at least one point");
    for (const JsonIn& p : items) {
      p.only_keys({"capacity", value_key});
      const JsonIn cap = p.at("capacity");
      const double bytes = entry(cap, Kind::bytes);
      if (!points.empty() && !(bytes > points.back().bytes))
        cap.fail("capacities must increase (this one is not larger than the previous point's)");
      points.push_back({bytes, entry(p.at(value_key), k)});
    }
    return SizeCurve(std::move(points));
  }

 private:
  std::set<std::string> sources_;
};

Tech::Unit read_unit(const Reader& r, const JsonIn& j) {
  j.only_keys({"area", "energy"});
  return {r.optional(j, "area", Kind::area), r.optional(j, "energy", Kind::energy)};
}

}  // namespace

Tech tech_from_json(const nlohmann::json& doc, const std::string& file) {
  const JsonIn root(doc, file);
  root.only_keys({"format", "name", "comment", "sources", "node", "fp_add", "fp_multiply", "fp_compare", "fp_inverse",
                  "register_file", "sram", "dram", "wire", "leakage"});
  const std::string format = root.at("format").string();
  if (format != "oprt-tech/1") root.at("format").fail("unsupported format \"" + format + "\" (expected oprt-tech/1)");

  std::set<std::string> ids;
  const JsonIn sources = root.at("sources");
  for (const auto& [id, s] : sources.members()) {
    s.only_keys({"cite", "where", "note"});
    if (s.at("cite").string().empty()) s.at("cite").fail("empty citation");
    if (s.at("where").string().empty()) s.at("where").fail("empty: say where in the source the numbers are");
    if (auto n = s.find("note")) n->string();
    ids.insert(id);
  }
  const Reader r(ids);

  Tech t;
  t.file = file;
  t.name = root.at("name").string();
  if (auto c = root.find("comment")) c->string();
  t.node_nm = r.optional(root, "node", Kind::length);
  if (auto j = root.find("fp_add")) t.fp_add = read_unit(r, *j);
  if (auto j = root.find("fp_multiply")) t.fp_multiply = read_unit(r, *j);
  if (auto j = root.find("fp_compare")) t.fp_compare = read_unit(r, *j);
  if (auto j = root.find("fp_inverse")) t.fp_inverse = read_unit(r, *j);
  if (auto j = root.find("register_file")) {
    j->only_keys({"area", "energy", "bytes", "access"});
    t.register_file.area_mm2 = r.optional(*j, "area", Kind::area);
    t.register_file.energy_pj = r.optional(*j, "energy", Kind::energy);
    t.register_file.bytes = r.optional(*j, "bytes", Kind::bytes);
    t.register_file.access_bytes = r.optional(*j, "access", Kind::bytes);
    if (t.register_file.area_mm2 && !t.register_file.bytes)
      j->fail("an \"area\" needs \"bytes\" (the capacity it is the area of)");
    if (t.register_file.energy_pj && !t.register_file.access_bytes)
      j->fail("an \"energy\" needs \"access\" (the bytes one access moves)");
  }
  if (auto j = root.find("sram")) {
    j->only_keys({"access", "read_energy", "area"});
    t.sram.access_bytes = r.optional(*j, "access", Kind::bytes);
    if (auto e = j->find("read_energy")) t.sram.read_energy_pj = r.curve(*e, "energy", Kind::energy);
    if (auto a = j->find("area")) t.sram.area_mm2 = r.curve(*a, "area", Kind::area);
    if (!t.sram.read_energy_pj.empty() && !t.sram.access_bytes)
      j->fail("a \"read_energy\" needs \"access\" (the bytes one access reads)");
  }
  if (auto j = root.find("dram")) {
    j->only_keys({"access", "energy_low", "energy_high"});
    t.dram.access_bytes = r.entry(j->at("access"), Kind::bytes);
    t.dram.energy_low_pj = r.entry(j->at("energy_low"), Kind::energy);
    t.dram.energy_high_pj = r.entry(j->at("energy_high"), Kind::energy);
    if (*t.dram.energy_high_pj < *t.dram.energy_low_pj) j->at("energy_high").fail("below energy_low");
  }
  if (auto j = root.find("wire")) {
    j->only_keys({"energy"});
    t.wire_pj_per_bit_mm = r.entry(j->at("energy"), Kind::wire);
  }
  if (auto j = root.find("leakage")) {
    j->only_keys({"power_density"});
    t.leakage_w_per_mm2 = r.entry(j->at("power_density"), Kind::power_density);
  }
  return t;
}

Tech load_tech(const std::string& path) { return tech_from_json(JsonIn::parse_file(path), path); }

}  // namespace oprt
