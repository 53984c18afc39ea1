#include "trace/wave_format.h"

#include "trace/buffered_file.h"

#include "fstapi.h"

#include <cerrno>
#include <charconv>
#include <cstdio>
#include <cstring>
#include <map>
#include <stdexcept>

namespace oprt {

namespace {

std::vector<std::string> split_scope(const std::string& s) {
  std::vector<std::string> parts;
  std::size_t b = 0;
  for (std::size_t e; (e = s.find('.', b)) != std::string::npos; b = e + 1) parts.push_back(s.substr(b, e - b));
  if (!s.empty()) parts.push_back(s.substr(b));
  return parts;
}

// Walks the variables grouped by scope, in scope order, calling open(name) / close() as the
// scope path changes and var(index) for each variable: viewers show the module hierarchy.
template <typename Open, typename Close, typename Var>
void walk_scopes(const std::vector<WaveVar>& vars, Open&& open, Close&& close, Var&& var) {
  std::map<std::string, std::vector<int>> scopes;
  for (std::size_t i = 0; i < vars.size(); ++i) scopes[vars[i].scope].push_back(static_cast<int>(i));
  std::vector<std::string> current;
  for (const auto& [scope, members] : scopes) {
    const std::vector<std::string> path = split_scope(scope);
    std::size_t common = 0;
    while (common < current.size() && common < path.size() && current[common] == path[common]) ++common;
    for (std::size_t i = current.size(); i > common; --i) close();
    for (std::size_t i = common; i < path.size(); ++i) open(path[i]);
    current = path;
    for (int v : members) var(v);
  }
  for (std::size_t i = current.size(); i > 0; --i) close();
}

// "00000000" to "11111111".
struct ByteBits {
  char bits[256][8];
  constexpr ByteBits() : bits() {
    for (int v = 0; v < 256; ++v)
      for (int b = 0; b < 8; ++b) bits[v][b] = static_cast<char>('0' + ((v >> (7 - b)) & 1));
  }
};
constexpr ByteBits kByteBitsTable;
constexpr const char (&kByteBits)[256][8] = kByteBitsTable.bits;

// VCD text, written through one large buffer: no stream, no string per change.
class VcdFormat final : public WaveFormat {
 public:
  explicit VcdFormat(const std::string& file) : out_(file) {}

  void declare(const std::vector<WaveVar>& vars) override {
    for (std::size_t i = 0; i < vars.size(); ++i) {  // identifiers: printable ASCII 33..126
      std::string code;
      std::size_t n = i;
      do {
        code += static_cast<char>(33 + n % 94);
        n /= 94;
      } while (n);
      codes_.push_back(code);
      widths_.push_back(vars[i].width);
    }
    std::string h = "$version oprt $end\n$timescale 1ps $end\n";
    walk_scopes(
        vars, [&](const std::string& s) { h += "$scope module " + s + " $end\n"; }, [&] { h += "$upscope $end\n"; },
        [&](int v) {
          h += "$var wire " + std::to_string(vars[v].width) + " " + codes_[v] + " " + vars[v].name + " $end\n";
        });
    h += "$enddefinitions $end\n";
    out_.put(h);
  }

  void time(std::uint64_t t) override {
    out_.room(32);
    char* p = out_.end();
    *p++ = '#';
    p = std::to_chars(p, p + 24, t).ptr;
    *p++ = '\n';
    out_.advance(p);
    last_ = t;
  }

  void value(int var, std::uint64_t v) override {
    const std::string& code = codes_[var];
    out_.room(80);
    char* p = out_.end();
    const int width = widths_[var];
    if (width < 64) v &= (std::uint64_t{1} << width) - 1;
    if (width == 1) {
      *p++ = v ? '1' : '0';
    } else {  // binary without leading zeros, a byte at a time
      *p++ = 'b';
      int bits = v ? 64 - __builtin_clzll(v) : 1;
      for (; bits % 8; --bits) *p++ = static_cast<char>('0' + ((v >> (bits - 1)) & 1));
      for (; bits; bits -= 8) {
        std::memcpy(p, kByteBits[(v >> (bits - 8)) & 0xff], 8);
        p += 8;
      }
      *p++ = ' ';
    }
    std::memcpy(p, code.data(), code.size());
    p += code.size();
    *p++ = '\n';
    out_.advance(p);
  }

  void finish(std::uint64_t end) override {
    if (end > last_) time(end);
    out_.close();
  }

 private:
  BufferedFile out_;
  std::vector<std::string> codes_;
  std::vector<int> widths_;
  std::uint64_t last_ = 0;
};

// GTKWave's FST through its own writer. fstapi keeps value changes in memory until it
// compresses them into a block (by default at 128 MB of them); blocks are closed here every
// kBlockChanges changes instead: less memory, and on the room frame a smaller file too
// (19.9 MB with 2^18, 22.4 MB with 2^21).
class FstFormat final : public WaveFormat {
 public:
  static constexpr std::uint64_t kBlockChanges = 1 << 18;

  explicit FstFormat(const std::string& file) : file_(file) {
    ctx_ = fstWriterCreate(file.c_str(), 1);
    if (!ctx_) throw std::runtime_error("cannot write " + file + ": " + std::strerror(errno));
    fstWriterSetTimescale(ctx_, -12);  // ps
    fstWriterSetPackType(ctx_, FST_WR_PT_ZLIB);  // half the size of LZ4's for about the same time
    fstWriterSetVersion(ctx_, "oprt");
  }
  ~FstFormat() override {
    if (ctx_) fstWriterClose(ctx_);  // abandoned: the caller removes the file
  }

  void declare(const std::vector<WaveVar>& vars) override {
    handles_.resize(vars.size());
    widths_.resize(vars.size());
    walk_scopes(
        vars, [&](const std::string& s) { fstWriterSetScope(ctx_, FST_ST_VCD_MODULE, s.c_str(), nullptr); },
        [&] { fstWriterSetUpscope(ctx_); },
        [&](int v) {
          widths_[v] = static_cast<std::uint32_t>(vars[v].width);
          handles_[v] = fstWriterCreateVar(ctx_, FST_VT_VCD_WIRE, FST_VD_IMPLICIT, widths_[v], vars[v].name.c_str(), 0);
        });
  }

  void time(std::uint64_t t) override {
    if (changes_ >= kBlockChanges) {
      fstWriterFlushContext(ctx_);
      changes_ = 0;
    }
    fstWriterEmitTimeChange(ctx_, t);
    last_ = t;
  }

  void value(int var, std::uint64_t v) override {
    fstWriterEmitValueChange64(ctx_, handles_[var], widths_[var], v);
    ++changes_;
  }

  void finish(std::uint64_t end) override {
    if (end > last_) fstWriterEmitTimeChange(ctx_, end);
    const bool failed = fstWriterGetFseekFailed(ctx_);
    fstWriterClose(ctx_);
    ctx_ = nullptr;
    if (failed) throw std::runtime_error("cannot write " + file_);
    std::FILE* f = std::fopen(file_.c_str(), "rb");  // fstapi reports write errors only on stderr
    if (!f || std::fseek(f, 0, SEEK_END) != 0 || std::ftell(f) <= 0) {
      if (f) std::fclose(f);
      throw std::runtime_error("cannot write " + file_);
    }
    std::fclose(f);
  }

 private:
  std::string file_;
  void* ctx_ = nullptr;
  std::vector<fstHandle> handles_;
  std::vector<std::uint32_t> widths_;
  std::uint64_t changes_ = 0, last_ = 0;
};

}  // namespace

bool is_fst_path(const std::string& path) {
  return path.size() >= 4 && path.compare(path.size() - 4, 4, ".fst") == 0;
}

std::unique_ptr<WaveFormat> open_wave_format(const std::string& path, const std::string& file) {
  if (is_fst_path(path)) return std::make_unique<FstFormat>(file);
  return std::make_unique<VcdFormat>(file);
}

std::vector<std::string> wave_side_files(const std::string& path, const std::string& file) {
  if (is_fst_path(path)) return {file + ".hier"};
  return {};
}

}  // namespace oprt
