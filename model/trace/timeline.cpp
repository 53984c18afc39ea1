#include "trace/timeline.h"

#include "ref/image.h"

#include <algorithm>
#include <cerrno>
#include <charconv>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <unistd.h>

namespace oprt {

namespace {
// JSON string contents: names here are module names and labels, but quote them anyway.
std::string json_escape(const std::string& s) {
  std::string o;
  for (char c : s) {
    if (c == '"' || c == '\\') o += '\\';
    if (static_cast<unsigned char>(c) < 0x20) continue;
    o += c;
  }
  return o;
}
}  // namespace

TimelineWriter::TimelineWriter(std::string path)
    : path_(std::move(path)), tmp_(temporary_path(path_)), out_(std::make_unique<BufferedFile>(tmp_)) {
  // Times are in microseconds (the format's unit), to the picosecond.
  put(R"({"displayTimeUnit":"ns","otherData":{"generator":"oprt"},"traceEvents":[)"
      "\n"
      R"({"ph":"M","pid":1,"name":"process_name","args":{"name":"oprt"}})");
}

TimelineWriter::~TimelineWriter() {
  if (closed_) return;
  out_.reset();  // abandoned (an error): leave no partial file behind
  std::remove(tmp_.c_str());
}

int TimelineWriter::track(const std::string& scope, const std::string& group, const std::string& label) {
  if (filter_ && !filter_(scope, group)) return kNotTraced;
  const int tid = ++tracks_;
  runs_.resize(static_cast<std::size_t>(tid) + 1);
  const std::string t = std::to_string(tid);
  put(",\n{\"ph\":\"M\",\"pid\":1,\"tid\":" + t + ",\"name\":\"thread_name\",\"args\":{\"name\":\"" +
      json_escape(label) + "\"}}");
  put(",\n{\"ph\":\"M\",\"pid\":1,\"tid\":" + t + ",\"name\":\"thread_sort_index\",\"args\":{\"sort_index\":" + t +
      "}}");
  return tid;
}

void TimelineWriter::set_window(std::uint64_t from, std::uint64_t to) {
  for (int t = 1; t <= tracks_; ++t) end_run(t);
  from_ = from;
  to_ = to;
}

void TimelineWriter::run_slice(int track, const char* name, std::uint64_t start, std::uint64_t end,
                               std::uint64_t ray) {
  if (track == kNotTraced) return;
  Run& r = runs_[static_cast<std::size_t>(track)];
  if (r.name && (std::strcmp(r.name, name) != 0 || r.end != start)) end_run(track);
  if (!r.name) {
    r.name = name;
    r.start = start;
    r.first = ray;
    r.rays = 0;
  }
  r.end = end;
  r.last = ray;
  ++r.rays;
}

void TimelineWriter::end_run(int track) {
  Run& r = runs_[static_cast<std::size_t>(track)];
  if (!r.name) return;
  const char* name = r.name;
  r.name = nullptr;
  if (r.rays == 1) slice(track, name, r.start, r.end, {{"ray", r.first}});
  else slice(track, name, r.start, r.end, {{"first_ray", r.first}, {"last_ray", r.last}, {"rays", r.rays}});
}

void TimelineWriter::slice(int track, const char* name, std::uint64_t start, std::uint64_t end,
                           std::initializer_list<Arg> args) {
  if (track == kNotTraced) return;
  end_run(track);
  start = std::max(start, from_);
  end = std::min(end, to_);
  if (end <= start) return;
  ++slices_;
  out_->room(512);
  put(R"(,
{"ph":"X","pid":1,"tid":)");
  put_uint(static_cast<std::uint64_t>(track));
  put(R"(,"name":")");
  put(name, std::strlen(name));
  put(R"(","ts":)");
  put_us(start);
  put(R"(,"dur":)");
  put_us(end - start);
  if (args.size()) {
    put(R"(,"args":{)");
    bool first = true;
    for (const Arg& a : args) {
      if (!first) put(",", 1);
      first = false;
      put("\"", 1);
      put(a.key, std::strlen(a.key));
      put("\":", 2);
      put_uint(a.value);
    }
    put("}", 1);
  }
  put("}", 1);
}

void TimelineWriter::put_uint(std::uint64_t v) {
  char s[24];
  put(s, static_cast<std::size_t>(std::to_chars(s, s + sizeof s, v).ptr - s));
}

// Picoseconds as decimal microseconds, exactly: "12.34", "0.00001", "7".
void TimelineWriter::put_us(std::uint64_t ps) {
  put_uint(ps / 1000000);
  std::uint64_t frac = ps % 1000000;
  if (!frac) return;
  char d[8] = {'.'};
  int n = 6;
  while (frac % 10 == 0) {
    frac /= 10;
    --n;
  }
  for (int i = n; i >= 1; --i, frac /= 10) d[i] = static_cast<char>('0' + frac % 10);
  put(d, static_cast<std::size_t>(n + 1));
}

void TimelineWriter::close() {
  if (closed_) return;
  for (int t = 1; t <= tracks_; ++t) end_run(t);
  put("\n]}\n");
  out_->close();
  std::filesystem::rename(tmp_, path_);
  closed_ = true;
}

}  // namespace oprt
