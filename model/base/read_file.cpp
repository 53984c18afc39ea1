#include "base/read_file.h"

#include "base/error.h"

#include <fstream>
#include <sstream>

namespace oprt {

std::string read_file_text(const std::string& path) {
  require_regular_file(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(path, "", "cannot open file");
  std::ostringstream ss;
  ss << in.rdbuf();
  if (in.bad()) throw InputError(path, "", "cannot read file");
  return ss.str();
}

}  // namespace oprt
