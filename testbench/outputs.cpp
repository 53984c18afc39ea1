#include "outputs.h"

#include "ref/image.h"
#include "base/error.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <unistd.h>

namespace oprt {

namespace fs = std::filesystem;

namespace {

// What a path is, for a message ("is a named pipe"), or "" for a regular file or nothing.
std::string not_regular(const fs::file_status& st) {
  switch (st.type()) {
    case fs::file_type::not_found:
    case fs::file_type::regular: return "";
    case fs::file_type::directory: return "is a folder, not a file";
    case fs::file_type::symlink: return "is a symbolic link (oprt replaces only regular files: name the file it points to)";
    case fs::file_type::block:
    case fs::file_type::character: return "is a device (oprt replaces only regular files)";
    case fs::file_type::fifo: return "is a named pipe (oprt replaces only regular files)";
    case fs::file_type::socket: return "is a socket (oprt replaces only regular files)";
    default: return "is not a regular file (oprt replaces only regular files)";
  }
}

bool writable(const fs::path& p, int mode) { return ::access(p.c_str(), mode) == 0; }

// A folder that will hold new files: it exists and can be written, or it can be created
// (its nearest existing ancestor is a folder that can be written).
std::string folder_problem(const fs::path& folder, bool is_the_output) {
  std::error_code ec;
  fs::path p = folder.empty() ? fs::path(".") : folder;
  for (;;) {
    const fs::file_status st = fs::status(p, ec);
    if (st.type() == fs::file_type::not_found) {
      const fs::path up = p.has_parent_path() && p.parent_path() != p ? p.parent_path() : fs::path(".");
      if (up == p) return "cannot be created";
      p = up;
      continue;
    }
    const std::string whose = p == folder ? std::string(is_the_output ? "" : "its folder ") : "its folder " + p.string() + " ";
    if (st.type() != fs::file_type::directory) {
      std::string what = not_regular(st);
      if (st.type() == fs::file_type::regular) what = "is a file";
      return whose.empty() ? what + ", not a folder" : whose + what.substr(0, what.find(" (")) + ", not a folder";
    }
    if (!writable(p, W_OK | X_OK)) return (whose.empty() ? std::string("is a folder ") : whose) + "oprt may not write into";
    return "";
  }
}

// A file to be replaced (or created): absent, or a regular file that may be written, in a
// folder that can be written or created.
std::string file_problem(const fs::path& file) {
  std::error_code ec;
  const fs::file_status st = fs::symlink_status(file, ec);
  if (std::string p = not_regular(st); !p.empty()) return p;
  if (st.type() == fs::file_type::regular && !writable(file, W_OK)) return "is a file oprt may not write (read-only)";
  return folder_problem(file.parent_path(), false);
}

fs::path canonical(const std::string& path) {
  std::error_code ec;
  fs::path p = fs::weakly_canonical(fs::absolute(path), ec);
  return ec ? fs::absolute(path).lexically_normal() : p;
}

// frame_NNNN.exr / .png: the frame's number, or -1.
long frame_of(const std::string& name) {
  if (name.rfind("frame_", 0) != 0) return -1;
  const auto dot = name.find('.', 6);
  if (dot == std::string::npos || dot == 6 || dot - 6 > 9) return -1;
  const std::string ext = name.substr(dot + 1), digits = name.substr(6, dot - 6);
  if (ext != "exr" && ext != "png") return -1;
  for (char c : digits)
    if (!std::isdigit(static_cast<unsigned char>(c))) return -1;
  const long f = std::stol(digits);
  return frame_name(static_cast<int>(f), ext.c_str()) == name ? f : -1;
}

bool is_within(const fs::path& inner, const fs::path& outer) {
  auto i = inner.begin();
  for (auto o = outer.begin(); o != outer.end(); ++o, ++i)
    if (i == inner.end() || *i != *o) return false;
  return i != inner.end();
}

}  // namespace

std::vector<std::string> trace_companions(const std::string& path) {
  const fs::path p(path);
  const std::string stem = p.stem().string();
  return {stem + ".gtkw", stem + "_state.txt", stem + "_stage.txt"};
}

void OutputPlan::folder(const std::string& option, const std::string& path, std::vector<std::string> names) {
  outputs_.push_back({option, path, true, std::move(names)});
}

void OutputPlan::file(const std::string& option, const std::string& path, std::vector<std::string> beside) {
  if (!path.empty()) outputs_.push_back({option, path, false, std::move(beside)});
}

void OutputPlan::input(const std::string& what, const std::string& path) {
  if (!path.empty()) inputs_.emplace_back(what, path);
}

void OutputPlan::check() const {
  // Each output on its own.
  for (const Output& o : outputs_) {
    const auto fail = [&](const std::string& problem) { throw InputError(o.option, o.path, problem); };
    if (o.folder) {
      if (std::string p = folder_problem(o.path, true); !p.empty()) fail(p);
      // The files it will replace in an existing folder: regular files only.
      std::error_code ec;
      for (fs::directory_iterator it(o.path, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        const long f = frame_of(name);
        const bool ours = (f >= 0 && (!frames_ || (f >= frames_->first && f <= frames_->second))) ||
                          std::find(o.names.begin(), o.names.end(), name) != o.names.end();
        if (!ours) continue;
        if (std::string p = file_problem(it->path()); !p.empty())
          throw InputError(o.option, o.path, name + " in it " + p + ", and the run writes a file of that name");
      }
    } else {
      if (std::string p = file_problem(o.path); !p.empty()) fail(p);
      for (const std::string& c : o.names) {
        const fs::path companion = fs::path(o.path).parent_path() / c;
        if (companion.filename() == fs::path(o.path).filename())
          fail("the run also writes " + c + " beside it (the GTKWave save file): the two would be one file");
        if (std::string p = file_problem(companion); !p.empty())
          fail(companion.string() + ", written beside it, " + p);
      }
    }
  }
  // No two outputs on one path, no output over an input, no file where a folder must be.
  struct Claim {
    fs::path path;
    const Output* owner;
    std::string what;  // what the owner writes there, for the message
    bool folder;       // the folder an output writes into (other outputs may lie inside it)
  };
  std::vector<Claim> claims;
  for (const Output& o : outputs_) {
    const fs::path p = canonical(o.path);
    const std::string who = o.option + " " + o.path;
    claims.push_back({p, &o, o.folder ? "the folder " + who + " writes into" : "the file " + who + " writes", o.folder});
    for (const std::string& n : o.names)
      claims.push_back({o.folder ? p / n : p.parent_path() / n, &o,
                        "the " + n + " that " + who + " writes" + (o.folder ? "" : " beside it"), false});
  }
  for (std::size_t i = 0; i < claims.size(); ++i) {
    const Claim& b = claims[i];
    for (std::size_t j = 0; j < i; ++j) {
      const Claim& a = claims[j];
      if (a.owner == b.owner) continue;
      // The same path, or a file where the other needs a folder.
      if (a.path == b.path || (is_within(a.path, b.path) && !b.folder) || (is_within(b.path, a.path) && !a.folder))
        throw InputError(b.owner->option, b.owner->path,
                         (a.path == b.path ? "is also " : "lies where ") + a.what + ": two outputs cannot share one path");
    }
    // A file output named like a frame the folder output writes.
    for (const Output& o : outputs_) {
      if (!o.folder || &o == b.owner || b.owner->folder) continue;
      const fs::path folder = canonical(o.path);
      const long f = frame_of(b.path.filename().string());
      if (b.path.parent_path() == folder && f >= 0 && (!frames_ || (f >= frames_->first && f <= frames_->second)))
        throw InputError(b.owner->option, b.owner->path,
                         "is also the file of frame " + std::to_string(f) + " that " + o.option + " " + o.path +
                             " writes: two outputs cannot share one path");
    }
    for (const auto& [what, path] : inputs_)
      if (canonical(path) == b.path)
        throw InputError(b.owner->option, b.owner->path, "is the " + what + " this run reads: oprt would replace it");
  }
}

void OutputPlan::create_folders() const {
  // The folders this call creates, outermost first: removed again if a later one fails, so
  // that a refused run leaves nothing behind.
  std::vector<fs::path> created;
  for (const Output& o : outputs_) {
    const fs::path folder = o.folder ? fs::path(o.path) : fs::path(o.path).parent_path();
    if (folder.empty()) continue;
    std::error_code ec;
    fs::path outermost;
    for (fs::path p = folder; !p.empty() && !fs::exists(p, ec); p = p.parent_path()) {
      outermost = p;
      if (p.parent_path() == p) break;
    }
    // check() saw a folder that can be written above the missing ones; creating them can
    // still fail where permissions say nothing (a file system that refuses new folders,
    // such as /proc, even to root): bad input too, named by its option.
    fs::create_directories(folder, ec);
    if (ec) {
      const std::string why = ec.message();
      for (auto c = created.rbegin(); c != created.rend(); ++c) fs::remove_all(*c, ec);
      throw InputError(o.option, o.path, "cannot create the folder " + folder.string() + ": " + why);
    }
    if (!outermost.empty()) created.push_back(outermost);
  }
}

}  // namespace oprt
