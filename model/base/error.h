// Every bad input ends in one of these: the file, the place in it (a JSON path such as
// /objects/3/mesh, or "line 12"), and the problem. The command line prints it as
// "FILE: PLACE: PROBLEM" and exits with status 2.
#pragma once

#include <filesystem>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace oprt {

class InputError : public std::runtime_error {
 public:
  InputError(std::string file, std::string place, std::string problem)
      : std::runtime_error(format(file, place, problem)),
        file_(std::move(file)), place_(std::move(place)), problem_(std::move(problem)) {
    remember(*this);
  }
  const std::string& file() const { return file_; }
  const std::string& place() const { return place_; }
  const std::string& problem() const { return problem_; }

  // An exception that leaves a SystemC process reaches sc_start only as SystemC's report
  // "uncaught exception" (E549) with its text: the renderer finds the InputError again by
  // that text, to report it as bad input (exit status 2) rather than as SystemC's error.
  static std::optional<InputError> thrown_with_text(const std::string& what) {
    const std::lock_guard<std::mutex> lock(recent_mutex_);
    for (const InputError& e : recent_)
      if (what == e.what()) return e;
    return std::nullopt;
  }

 private:
  static void remember(const InputError& e) {
    const std::lock_guard<std::mutex> lock(recent_mutex_);
    if (recent_.size() == 8) recent_.erase(recent_.begin());
    recent_.push_back(e);
  }
  inline static std::mutex recent_mutex_;
  inline static std::vector<InputError> recent_;

  static std::string format(const std::string& f, const std::string& p, const std::string& q) {
    std::string s = f.empty() ? std::string("<input>") : f;
    if (!p.empty()) s += ": " + p;
    return s + ": " + q;
  }
  std::string file_, place_, problem_;
};

// Every file a loader opens must be a regular file: a directory would read as empty, a
// device such as /dev/zero would be read until memory runs out, a pipe would block.
inline void require_regular_file(const std::string& path, const std::string& place = "") {
  std::error_code ec;
  const auto st = std::filesystem::status(path, ec);
  if (ec || st.type() == std::filesystem::file_type::not_found) throw InputError(path, place, "no such file");
  if (st.type() == std::filesystem::file_type::directory) throw InputError(path, place, "is a directory, not a file");
  if (st.type() != std::filesystem::file_type::regular)
    throw InputError(path, place, "is not a regular file (a device, pipe or socket)");
}

}  // namespace oprt
