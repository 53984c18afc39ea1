#include "trace/buffered_file.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <stdexcept>

namespace oprt {

BufferedFile::BufferedFile(std::string file, std::size_t bytes) : file_(std::move(file)), buf_(bytes) {
  f_ = std::fopen(file_.c_str(), "wb");
  if (!f_) throw std::runtime_error("cannot write " + file_ + ": " + std::strerror(errno));
  std::setvbuf(f_, nullptr, _IONBF, 0);
}

BufferedFile::~BufferedFile() {
  if (f_) std::fclose(f_);
}

void BufferedFile::put(const char* s, std::size_t len) {
  for (std::size_t done = 0; done < len;) {
    if (n_ == buf_.size()) drain();
    const std::size_t k = std::min(len - done, buf_.size() - n_);
    std::memcpy(buf_.data() + n_, s + done, k);
    n_ += k;
    done += k;
  }
}

void BufferedFile::drain() {
  if (n_ && std::fwrite(buf_.data(), 1, n_, f_) != n_)
    throw std::runtime_error("cannot write " + file_ + ": " + std::strerror(errno));
  n_ = 0;
}

void BufferedFile::close() {
  drain();
  const int rc = std::fclose(f_);
  f_ = nullptr;
  if (rc != 0) throw std::runtime_error("cannot write " + file_ + ": " + std::strerror(errno));
}

}  // namespace oprt
