// Every bad input ends in one of these: the file, the place in it (a JSON path such as
// /objects/3/mesh, or "line 12"), and the problem. The command line prints it as
// "FILE: PLACE: PROBLEM" and exits with status 2.
#pragma once

#include <stdexcept>
#include <string>

namespace oprt {

class InputError : public std::runtime_error {
 public:
  InputError(std::string file, std::string place, std::string problem)
      : std::runtime_error(format(file, place, problem)),
        file_(std::move(file)), place_(std::move(place)), problem_(std::move(problem)) {}
  const std::string& file() const { return file_; }
  const std::string& place() const { return place_; }
  const std::string& problem() const { return problem_; }

 private:
  static std::string format(const std::string& f, const std::string& p, const std::string& q) {
    std::string s = f.empty() ? std::string("<input>") : f;
    if (!p.empty()) s += ": " + p;
    return s + ": " + q;
  }
  std::string file_, place_, problem_;
};

}  // namespace oprt
