// A VCD file for GTKWave, written from timestamped value changes. Changes may be reported
// out of time order (a unit reports the phases of a ray when it starts it; units whose
// timing nothing else observes run ahead of simulation time), so they are buffered and
// written in time order up to a horizon no process can report behind: the current
// simulation time, which every process's local time is at or after. Of several changes of
// one variable at one time only the last is written, and variables in declaration order:
// the file depends only on the values at each time, not on the order they were reported
// in. Plain C++ (times in picoseconds).
#pragma once

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

namespace oprt {

class VcdWriter {
 public:
  explicit VcdWriter(std::string path);
  ~VcdWriter();

  // Declare a variable before the first change; returns its handle.
  int add(const std::string& scope, const std::string& name, int width);
  // A counter: its value is the sum of the deltas reported up to each time, in time order
  // (a FIFO's occupancy, whose pushes and pops are reported by different processes).
  int add_counter(const std::string& scope, const std::string& name, int width);
  void change(int var, std::uint64_t time_ps, std::uint64_t value);
  void change_by(int var, std::uint64_t time_ps, std::int64_t delta);
  // Write every buffered change before `horizon_ps`.
  void flush_before(std::uint64_t horizon_ps);
  // Forget buffered changes at or after t_ps (a frame abandoned when the run was stopped).
  void discard_from(std::uint64_t t_ps);
  // Write everything, end the dump at end_ps, and move the file into place.
  void close(std::uint64_t end_ps);
  const std::string& path() const { return path_; }
  // Declared variables as ("scope.name", width), in declaration order.
  std::vector<std::pair<std::string, int>> variables() const;

 private:
  struct Var {
    std::string scope, name, code;
    int width;
    bool counter = false;
    std::uint64_t value = 0, last = ~0ULL;
    bool touched = false;
  };
  struct Change { std::uint64_t time, seq; int var; std::uint64_t value; };
  void header();
  void write(const Var& v);
  std::string path_, tmp_;
  std::ofstream out_;
  std::vector<Var> vars_;
  std::vector<Change> buffer_;
  std::vector<int> touched_;
  std::uint64_t seq_ = 0, written_time_ = ~0ULL;
  bool started_ = false, closed_ = false;
};

}  // namespace oprt
