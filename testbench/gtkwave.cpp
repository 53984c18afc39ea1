#include "gtkwave.h"

#include "ref/image.h"
#include "trace_select.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <stdexcept>

namespace oprt {

namespace {
// GTKWave trace flags (gtkwave's save-file format): decimal + right-justified, the same
// translated through filter file 1, and the group markers.
constexpr const char* kDec = "@24";
constexpr const char* kDecNamed = "@2024";
constexpr const char* kBit = "@28";
constexpr const char* kGroupBegin = "@800200";
constexpr const char* kGroupEnd = "@1000200";

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}
}  // namespace

void write_gtkwave_save(const std::string& trace_path, const std::string& save_path,
                        const std::vector<TraceSignal>& signals, std::uint64_t start_ps, std::uint64_t end_ps) {
  namespace fs = std::filesystem;
  const fs::path save = fs::absolute(save_path);
  const fs::path filter = save.parent_path() / (save.stem().string() + "_state.txt");
  write_atomically(filter.string(), [&](const std::string& tmp) {
    std::ofstream f(tmp);
    f << "0 idle\n1 sphere\n2 transform\n3 primitive\n4 stall\n5 box\n6 node\n";
    f.close();
    if (!f) throw std::runtime_error("cannot write " + tmp);
  });
  std::vector<std::string> gpp, bus;
  std::map<int, std::vector<std::string>> unit;  // unit -> its signals
  for (const TraceSignal& sig : signals) {
    const std::string& s = sig.name;
    // GTKWave names a vector with its bit range.
    const std::string full = sig.width > 1 ? s + "[" + std::to_string(sig.width - 1) + ":0]" : s;
    const auto dot = s.rfind('.');
    const SignalKind k = classify_signal(dot == std::string::npos ? "" : s.substr(0, dot), s.substr(dot + 1));
    if (k.unit >= 0) unit[k.unit].push_back(full);
    else if (k.group == "bus") bus.push_back(full);
    else gpp.push_back(full);
  }
  write_atomically(save.string(), [&](const std::string& tmp) {
    std::ofstream g(tmp);
    g << "[*] oprt trace: GPP, bus, and per intersection unit its state (pipelined: whether each of its units issues, the "
         "operations waiting for it, the rays waiting for memory and the rays in flight), its ray FIFO's occupancy and its cache misses outstanding\n";
    g << "[dumpfile] \"" << fs::absolute(trace_path).string() << "\"\n";
    g << "[savefile] \"" << save.string() << "\"\n[timestart] " << start_ps << "\n[sst_expanded] 1\n";
    // GTKWave's zoom is -log2(time units per pixel): fit the whole trace in the window (GTKWave counts zoom against a
    // narrower reference width than the window; 250 was found by looking).
    const double span = static_cast<double>(end_ps > start_ps ? end_ps - start_ps : 1);
    g << "*" << -std::log2(std::max<double>(1.0, span / 250)) << " " << start_ps << "\n";
    if (!gpp.empty() || !bus.empty()) {
      g << kGroupBegin << "\n-GPP and bus\n";
      for (const auto& s : gpp) g << kDec << "\n" << s << "\n";
      for (const auto& s : bus) g << kBit << "\n" << s << "\n";
      g << kGroupEnd << "\n-GPP and bus\n";
    }
    for (const auto& [u, sigs] : unit) {
      const std::string name = "IU " + std::to_string(u);
      g << kGroupBegin << "\n-" << name << "\n";
      for (const auto& s : sigs) {
        if (ends_with(s, ".state[2:0]")) g << "^1 " << filter.string() << "\n" << kDecNamed << "\n" << s << "\n";
        else g << kDec << "\n" << s << "\n";
      }
      g << kGroupEnd << "\n-" << name << "\n";
    }
    g.close();
    if (!g) throw std::runtime_error("cannot write " + tmp);
  });
}

}  // namespace oprt
