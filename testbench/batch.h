// oprt batch: many renders of one scene in one process (batch_cmd.cpp).
#pragma once

#include "render.h"

#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

namespace oprt {

struct BatchOptions {
  std::string scene, archs, out;
};

// A line whose options render's command line refuses (exit status 2, the message as render's).
struct LineRefused : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// One line's options (as `oprt render` takes them, without the scene) -> its RenderOptions;
// throws InputError or LineRefused on a bad option. main.cpp parses them with render's own command line.
using RenderParser = std::function<RenderOptions(const std::vector<std::string>&)>;

int run_batch(const BatchOptions& b, const RenderParser& parse);

}  // namespace oprt
