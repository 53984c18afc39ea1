#include "hw/vcd_writer.h"

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <map>
#include <stdexcept>
#include <unistd.h>

namespace oprt {

namespace {
std::string code_for(std::size_t i) {  // VCD identifiers: printable ASCII 33..126
  std::string s;
  do {
    s += static_cast<char>(33 + i % 94);
    i /= 94;
  } while (i);
  return s;
}
}  // namespace

VcdWriter::VcdWriter(std::string path) : path_(std::move(path)) {
  const std::filesystem::path p(path_);
  tmp_ = (p.parent_path() / ("." + p.filename().string() + ".tmp" + std::to_string(::getpid()))).string();
}

VcdWriter::~VcdWriter() {
  if (!closed_) {  // abandoned (an error): leave no partial file behind
    out_.close();
    std::remove(tmp_.c_str());
  }
}

int VcdWriter::add(const std::string& scope, const std::string& name, int width) {
  if (started_) throw std::logic_error("VcdWriter: variable declared after the first change");
  vars_.push_back({scope, name, code_for(vars_.size()), width});
  return static_cast<int>(vars_.size() - 1);
}

int VcdWriter::add_counter(const std::string& scope, const std::string& name, int width) {
  const int v = add(scope, name, width);
  vars_[v].counter = true;
  return v;
}

void VcdWriter::change_by(int var, std::uint64_t time_ps, std::int64_t delta) {
  change(var, time_ps, static_cast<std::uint64_t>(delta));
}

void VcdWriter::header() {
  out_.open(tmp_);
  if (!out_) throw std::runtime_error("cannot write " + tmp_);
  out_ << "$version oprt $end\n$timescale 1ps $end\n";
  // Scopes are dotted SystemC names ("testbench.engine.iu3"): nest them, so that viewers
  // show the module hierarchy.
  std::map<std::string, std::vector<const Var*>> scopes;
  for (const Var& v : vars_) scopes[v.scope].push_back(&v);
  std::vector<std::string> open;  // current scope path
  auto split = [](const std::string& s) {
    std::vector<std::string> parts;
    std::size_t b = 0;
    for (std::size_t e; (e = s.find('.', b)) != std::string::npos; b = e + 1) parts.push_back(s.substr(b, e - b));
    if (!s.empty()) parts.push_back(s.substr(b));
    return parts;
  };
  for (const auto& [scope, vs] : scopes) {
    const std::vector<std::string> path = split(scope);
    std::size_t common = 0;
    while (common < open.size() && common < path.size() && open[common] == path[common]) ++common;
    for (std::size_t i = open.size(); i > common; --i) out_ << "$upscope $end\n";
    for (std::size_t i = common; i < path.size(); ++i) out_ << "$scope module " << path[i] << " $end\n";
    open = path;
    for (const Var* v : vs) out_ << "$var wire " << v->width << " " << v->code << " " << v->name << " $end\n";
  }
  for (std::size_t i = open.size(); i > 0; --i) out_ << "$upscope $end\n";
  out_ << "$enddefinitions $end\n";
  started_ = true;
  // Every variable starts at 0 (no X in the viewer before its first change).
  for (std::size_t v = 0; v < vars_.size(); ++v) buffer_.push_back({0, seq_++, static_cast<int>(v), 0});
}

void VcdWriter::change(int var, std::uint64_t time_ps, std::uint64_t value) {
  if (!started_) header();
  buffer_.push_back({time_ps, seq_++, var, value});
}

void VcdWriter::write(const Var& v) {
  if (v.width == 1) {
    out_ << (v.value ? '1' : '0') << v.code << '\n';
    return;
  }
  char bits[72];
  int n = 0;
  for (int b = v.width - 1; b >= 0; --b)
    if (n || (v.value >> b) & 1 || b == 0) bits[n++] = ((v.value >> b) & 1) ? '1' : '0';
  bits[n] = 0;
  out_ << 'b' << bits << ' ' << v.code << '\n';
}

void VcdWriter::flush_before(std::uint64_t horizon) {
  if (!started_) header();
  std::sort(buffer_.begin(), buffer_.end(),
            [](const Change& a, const Change& b) { return a.time != b.time ? a.time < b.time : a.seq < b.seq; });
  std::size_t i = 0;
  while (i < buffer_.size() && buffer_[i].time < horizon) {
    const std::uint64_t t = buffer_[i].time;
    for (; i < buffer_.size() && buffer_[i].time == t; ++i) {
      Var& v = vars_[buffer_[i].var];
      v.value = v.counter ? v.value + buffer_[i].value : buffer_[i].value;  // counters: wrapping sum of deltas
      if (!v.touched) {
        v.touched = true;
        touched_.push_back(buffer_[i].var);
      }
    }
    std::sort(touched_.begin(), touched_.end());
    bool stamped = false;
    for (int k : touched_) {
      Var& v = vars_[k];
      v.touched = false;
      if (v.value == v.last) continue;
      if (!stamped) {
        out_ << '#' << t << '\n';
        written_time_ = t;
        stamped = true;
      }
      v.last = v.value;
      write(v);
    }
    touched_.clear();
  }
  buffer_.erase(buffer_.begin(), buffer_.begin() + static_cast<std::ptrdiff_t>(i));
}

std::vector<std::pair<std::string, int>> VcdWriter::variables() const {
  std::vector<std::pair<std::string, int>> n;
  for (const Var& v : vars_) n.emplace_back(v.scope.empty() ? v.name : v.scope + "." + v.name, v.width);
  return n;
}

void VcdWriter::discard_from(std::uint64_t t) {
  buffer_.erase(std::remove_if(buffer_.begin(), buffer_.end(), [&](const Change& c) { return c.time >= t; }),
                buffer_.end());
}

void VcdWriter::close(std::uint64_t end_ps) {
  flush_before(~0ULL);
  if (written_time_ == ~0ULL || end_ps > written_time_) out_ << '#' << end_ps << '\n';
  out_.close();
  if (!out_) throw std::runtime_error("cannot write " + tmp_);
  std::filesystem::rename(tmp_, path_);
  closed_ = true;
}

}  // namespace oprt
