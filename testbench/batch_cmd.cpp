// oprt batch SCENE --archs FILE.jsonl --out DIR: many renders of one scene in one process, at
// the analytic level. Each line of FILE.jsonl is {"args": [...]}, the options of one `oprt render`
// (without the scene and --out), and optionally "out": its own folder; line i (from 0) renders
// into DIR/i (or its "out") as `oprt render SCENE ARGS --out DIR/i` would, and DIR/i/status.json records how it ended ({"exit": 0 | 1 | 2,
// "message": ...}, the exit status and message that render would have given). The scene is
// loaded once, and the spheres and BVHs are built once per set of the options that shape them
// (render.h, RenderCache). SystemC elaborates once per process, so a batch refuses --level at
// and lt: their renders run as separate `oprt render` processes.
#include "batch.h"

#include "render.h"
#include "base/error.h"
#include "ref/stop.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <string>
#include <vector>

namespace oprt {

namespace {

namespace fs = std::filesystem;

struct Line {
  std::vector<std::string> args;
  std::string out;  // "": DIR/i
};

// Every line read and checked before anything renders: FILE:LINE: problem, exit status 2.
std::vector<Line> read_lines(const std::string& file) {
  std::ifstream in(file);
  if (!in) throw InputError(file, "", "cannot read the batch file");
  std::vector<Line> lines;
  std::string text;
  int number = 0;
  while (std::getline(in, text)) {
    ++number;
    if (text.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::string where = "line " + std::to_string(number);
    nlohmann::json j;
    try {
      j = nlohmann::json::parse(text);
    } catch (const nlohmann::json::parse_error& e) {
      throw InputError(file, where, std::string("not JSON: ") + e.what());
    }
    if (!j.is_object() || !j.contains("args") || !j["args"].is_array())
      throw InputError(file, where, "expected {\"args\": [the options of one oprt render, as strings]}");
    Line line;
    if (j.contains("out")) {
      if (!j["out"].is_string() || j["out"].get<std::string>().empty())
        throw InputError(file, where, "\"out\" must be a folder's name");
      line.out = j["out"].get<std::string>();
    }
    for (const auto& a : j["args"]) {
      if (!a.is_string()) throw InputError(file, where, "every element of \"args\" must be a string");
      const std::string s = a.get<std::string>();
      for (const char* reserved : {"--out", "--vcd", "--timeline", "--check"})
        if (s == reserved) throw InputError(file, where, s + ": the batch chooses each render's outputs; not an option here");
      line.args.push_back(s);
    }
    lines.push_back(std::move(line));
  }
  if (lines.empty()) throw InputError(file, "", "no lines: nothing to render");
  return lines;
}

void write_status(const fs::path& dir, int exit, const std::string& message) {
  fs::create_directories(dir);
  const fs::path tmp = dir / ".status.json.tmp";
  {
    std::ofstream out(tmp);
    out << nlohmann::json{{"exit", exit}, {"message", message}}.dump() << "\n";
  }
  fs::rename(tmp, dir / "status.json");
}

}  // namespace

int run_batch(const BatchOptions& b, const RenderParser& parse) {
  const std::vector<Line> lines = read_lines(b.archs);
  if (fs::exists(b.out) && !fs::is_directory(b.out)) throw InputError("--out", b.out, "exists and is not a folder");
  fs::create_directories(b.out);
  const auto cache = make_render_cache();
  int failures = 0;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    const fs::path dir = lines[i].out.empty() ? fs::path(b.out) / std::to_string(i) : fs::path(lines[i].out);
    std::error_code ec;
    fs::remove(dir / "status.json", ec);
    int exit = 0;
    std::string message;
    try {
      RenderOptions ro = parse(lines[i].args);
      ro.scene = b.scene;
      ro.out = dir.string();
      ro.progress = false;
      if (ro.level && *ro.level != "analytic")
        throw InputError(b.archs, "line " + std::to_string(i + 1),
                         "--level " + *ro.level + ": a batch renders at the analytic level only (SystemC elaborates once "
                         "per process); run oprt render for each");
      ro.level = "analytic";
      exit = run_render(ro, cache.get());
    } catch (const InputError& e) {
      exit = 2;
      message = e.what();
    } catch (const LineRefused& e) {
      exit = 2;
      message = e.what();
    } catch (const Interrupted&) {
      throw;  // the whole batch stops (main reports it)
    } catch (const std::bad_alloc&) {
      exit = 1;
      message = "out of memory";
    } catch (const std::exception& e) {
      exit = 1;
      message = std::string("error: ") + e.what();
    }
    if (!message.empty()) std::cerr << "oprt: batch line " << i + 1 << ": " << message << "\n";
    write_status(dir, exit, message);
    failures += exit != 0;
  }
  std::printf("oprt: batch: %zu renders, %d refused or failed (DIR/N/status.json)\n", lines.size(), failures);
  return 0;
}

}  // namespace oprt
