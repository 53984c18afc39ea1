#include "gtkwave.h"

#include "ref/image.h"

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

void write_gtkwave_save(const std::string& vcd_path, const std::string& save_path,
                        const std::vector<TraceSignal>& signals, std::uint64_t end_ps) {
  namespace fs = std::filesystem;
  const fs::path save = fs::absolute(save_path);
  const fs::path filter = save.parent_path() / (save.stem().string() + "_state.txt");
  write_atomically(filter.string(), [&](const std::string& tmp) {
    std::ofstream f(tmp);
    f << "0 idle\n1 sphere\n2 transform\n3 primitive\n4 stall\n5 box\n";
    f.close();
    if (!f) throw std::runtime_error("cannot write " + tmp);
  });
  // A pipelined unit's stages (hw/pipeline_timing.h StageState).
  const fs::path stage_filter = save.parent_path() / (save.stem().string() + "_stage.txt");
  const bool pipelined = std::any_of(signals.begin(), signals.end(),
                                     [](const TraceSignal& t) { return t.name.find(".stage.") != std::string::npos; });
  if (pipelined)
    write_atomically(stage_filter.string(), [&](const std::string& tmp) {
      std::ofstream f(tmp);
      f << "0 waiting\n1 busy\n2 full\n3 memory\n";
      f.close();
      if (!f) throw std::runtime_error("cannot write " + tmp);
    });
  std::vector<std::string> gpp, bus;
  std::map<int, std::vector<std::string>> unit;  // unit -> its signals
  for (const TraceSignal& sig : signals) {
    const std::string& s = sig.name;
    // GTKWave names a vector with its bit range.
    const std::string full = sig.width > 1 ? s + "[" + std::to_string(sig.width - 1) + ":0]" : s;
    if (s.find(".gpp.") != std::string::npos) gpp.push_back(full);
    else if (s.find(".bus.") != std::string::npos) bus.push_back(full);
    else {
      for (const char* kind : {".iu", ".fifo"}) {
        const auto at = s.find(kind);
        if (at == std::string::npos) continue;
        unit[std::stoi(s.substr(at + std::string(kind).size()))].push_back(full);
      }
    }
  }
  write_atomically(save.string(), [&](const std::string& tmp) {
    std::ofstream g(tmp);
    g << "[*] oprt trace: GPP, bus, and per intersection unit its state (pipelined: each stage's state, its queues and "
         "rays in flight) and ray FIFO occupancy\n";
    g << "[dumpfile] \"" << fs::absolute(vcd_path).string() << "\"\n";
    g << "[savefile] \"" << save.string() << "\"\n[timestart] 0\n[sst_expanded] 1\n";
    // GTKWave's zoom is -log2(time units per pixel): fit the whole trace in the window (GTKWave counts zoom against a
    // narrower reference width than the window; 250 was found by looking).
    g << "*" << -std::log2(std::max<double>(1.0, static_cast<double>(end_ps) / 250)) << " 0\n";
    g << kGroupBegin << "\n-GPP and bus\n";
    for (const auto& s : gpp) g << kDec << "\n" << s << "\n";
    for (const auto& s : bus) g << kBit << "\n" << s << "\n";
    g << kGroupEnd << "\n-GPP and bus\n";
    for (const auto& [u, sigs] : unit) {
      const std::string name = "IU " + std::to_string(u);
      g << kGroupBegin << "\n-" << name << "\n";
      for (const auto& s : sigs) {
        if (ends_with(s, ".state[2:0]")) g << "^1 " << filter.string() << "\n" << kDecNamed << "\n" << s << "\n";
        else if (s.find(".stage.") != std::string::npos && ends_with(s, "[1:0]"))
          g << "^1 " << stage_filter.string() << "\n" << kDecNamed << "\n" << s << "\n";
        else g << kDec << "\n" << s << "\n";
      }
      g << kGroupEnd << "\n-" << name << "\n";
    }
    g.close();
    if (!g) throw std::runtime_error("cannot write " + tmp);
  });
}

}  // namespace oprt
