#include "frame_log.h"

#include "ref/image.h"

#include <cstdio>
#include <stdexcept>

namespace oprt {

FrameLog::FrameLog(std::string path) : path_(std::move(path)), spool_path_(temporary_path(path_ + ".frames")) {}

FrameLog::~FrameLog() {
  spool_.close();
  std::remove(spool_path_.c_str());
}

void FrameLog::add(const nlohmann::json& frame) {
  if (!spool_.is_open()) {
    spool_.open(spool_path_, std::ios::binary | std::ios::trunc);
    if (!spool_) throw std::runtime_error("cannot write " + spool_path_);
  }
  spool_ << (frames_ ? ",\n" : "") << frame.dump();
  spool_.flush();
  if (!spool_) throw std::runtime_error("cannot write " + spool_path_);
  ++frames_;
}

void FrameLog::write(const nlohmann::json& head) {
  if (frames_ == 0) return;
  write_atomically(path_, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary);
    std::string text = head.dump(1);  // "{\n ...\n}": the frames go before its closing brace
    text.erase(text.find_last_of('}'));
    while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
    out << text << (head.empty() ? "\n" : ",\n") << " \"frames\": [\n";
    std::ifstream spool(spool_path_, std::ios::binary);
    out << spool.rdbuf() << "\n ]\n}\n";
    out.close();  // a failed flush (disk full) must not be renamed into place
    if (!out || spool.bad()) throw std::runtime_error("cannot write " + tmp);
  });
}

}  // namespace oprt
