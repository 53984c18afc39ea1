// Published scenes as they are (issue 15): every BART .aff under ../shared/bart that has a
// view loads, with its known triangle and frame counts and the warnings its quirks earn, and
// what is animated really moves while what is static stays. Load only: no frame is rendered.
#include "scene/load.h"

#include <catch2/catch.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

using namespace oprt;

namespace {
namespace fs = std::filesystem;
const fs::path kBart = fs::path(OPRT_SHARED_DIR) / "bart";

// Whether an .aff file has a view statement: a `v` token outside comments.
bool has_view(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  for (std::string line; std::getline(in, line);) {
    line = line.substr(0, line.find_first_of("#%"));
    std::istringstream words(line);
    for (std::string w; words >> w;)
      if (w == "v") return true;
  }
  return false;
}

struct Published {
  std::size_t triangles;
  int frames;
  // Each warning the file earns, by the start of its text (file relative to kBart).
  std::vector<std::string> warnings;
};

// Counts from `oprt info` on the published files (110,561 is the kitchen's published count).
const std::map<std::string, Published>& published() {
  static const std::map<std::string, Published> p = {
      {"kitchen/kitchen.aff",
       {110561, 800,
        {"kitchen/car_rotating_wheel_left.aff: line 9: 'rot' keys of 'k rotating_wheel_left': a time repeats: "
         "key 27 of 127 (line 36) at time 7.16",
         "kitchen/car_rotating_wheel_right.aff: line 8: 'rot' keys of 'k rotating_wheel_right': a time repeats: "
         "key 27 of 127 (line 35) at time 7.16"}}},
      {"museum/museum5.aff", {11564, 300, {}}},
  };
  return p;
}

Vec3d world(const Object& o, double frame, std::size_t v) {
  if (o.deform) {
    std::vector<Vec3d> vs;
    o.deform->at(frame, vs);
    return o.motion->at(frame).point(vs.at(v));
  }
  return o.motion->at(frame).point(o.mesh.vertices.at(v));
}
}  // namespace

TEST_CASE("published: every BART scene with a view loads, and moves where it must", "[bart][published]") {
  INFO("BART scenes expected under " << kBart);
  REQUIRE(fs::is_directory(kBart));
  std::vector<std::string> with_view;
  for (const auto& e : fs::recursive_directory_iterator(kBart))
    if (e.path().extension() == ".aff" && has_view(e.path()))
      with_view.push_back(fs::relative(e.path(), kBart).generic_string());
  std::sort(with_view.begin(), with_view.end());
  std::vector<std::string> known;
  for (const auto& [name, p] : published()) known.push_back(name);
  // A new published file with a view must be added to the table above, with its counts.
  CHECK(with_view == known);

  for (const std::string& name : with_view) {
    INFO(name);
    const auto it = published().find(name);
    if (it == published().end()) continue;
    const Published& want = it->second;
    LoadOptions quiet;
    quiet.print_warnings = false;
    const Scene s = load_scene((kBart / name).string(), quiet);
    CHECK(s.triangle_count() == want.triangles);
    CHECK(s.frame_count == want.frames);
    REQUIRE(s.warnings.size() == want.warnings.size());
    for (std::size_t i = 0; i < want.warnings.size(); ++i) {
      INFO(s.warnings[i]);
      CHECK(s.warnings[i].rfind((kBart / want.warnings[i]).lexically_normal().string(), 0) == 0);
    }

    // Eight frames across the animation: every animated object (and every deforming one)
    // leaves its frame-0 place at one of them at least, every static one never does.
    const int last = s.frame_count - 1;
    std::vector<int> frames;
    for (int k = 1; k <= 8; ++k) frames.push_back(last * k / 8);
    std::size_t moving = 0;
    for (const Object& o : s.objects) {
      INFO(o.name);
      const bool animated = o.motion->animated() || o.deform;
      moving += animated;
      const Vec3d p0 = world(o, 0, 0);
      bool moved = false;
      for (int f : frames) moved = moved || glm::length(world(o, f, 0) - p0) > 1e-9;
      CHECK(moved == animated);
    }
    CHECK(moving > 0);
    // Both cameras fly (`k camera`).
    CHECK(glm::length(s.camera->at(last / 2).eye - s.camera->at(0).eye) > 0.1);
  }
}
