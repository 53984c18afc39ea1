// A whole input file as text, its bytes as they are. Throws InputError naming the file if it
// is not a regular file (error.h), or cannot be opened or read.
#pragma once

#include <string>

namespace oprt {

std::string read_file_text(const std::string& path);

}  // namespace oprt
