// A file written through one large buffer: no stream, no string per write. What the trace
// writers (the VCD text, the timeline) write with. Every failure throws std::runtime_error
// "cannot write FILE: REASON".
#pragma once

#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

namespace oprt {

class BufferedFile {
 public:
  explicit BufferedFile(std::string file, std::size_t bytes = 1 << 20);
  ~BufferedFile();  // closes the file if close() has not (an error path: no exception)
  BufferedFile(const BufferedFile&) = delete;
  BufferedFile& operator=(const BufferedFile&) = delete;

  void put(const char* s, std::size_t len);
  void put(const std::string& s) { put(s.data(), s.size()); }
  // Room for `bytes` more at end(); the caller writes them there and hands back where it
  // stopped (advance).
  void room(std::size_t bytes) {
    if (n_ + bytes > buf_.size()) drain();
  }
  char* end() { return buf_.data() + n_; }
  void advance(char* p) { n_ = static_cast<std::size_t>(p - buf_.data()); }
  // Writes what is buffered and closes the file.
  void close();

 private:
  void drain();
  std::string file_;
  std::FILE* f_ = nullptr;
  std::vector<char> buf_;
  std::size_t n_ = 0;
};

}  // namespace oprt
