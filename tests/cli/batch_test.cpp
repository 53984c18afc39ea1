// oprt batch: many analytic renders of one scene in one process (the scene loaded once, each
// set of spheres and BVHs built once) write what separate `oprt render` runs write.
#include "cli_util.h"

#include <catch2/catch.hpp>

#include <vector>

using namespace oprt::test;

namespace {

// Architectures that share the geometry (lines 0, 2 and 4: brute force, one sphere per object)
// and that do not (BVHs, subdivided spheres, double precision), over two frames of an animated
// scene: a render that takes its geometry from the cache after another has animated it must
// start from the scene's frame 0 all the same.
const std::vector<std::string> kLines = {
    "--ius 4 --balance paper",
    "--ius 8 --accel bvh --top bvh",
    "--ius 4 --balance sa_n --iu pipelined",
    "--ius 6 --subdivide 4 --accel bvh --precision double",
    "--ius 5 --route multicast --balance spatial",
};

std::string json_args(const std::string& common, const std::string& line) {
  std::string out = "{\"args\": [";
  std::string words = common + " " + line, w;
  bool first = true;
  for (std::size_t i = 0; i <= words.size(); ++i) {
    if (i == words.size() || words[i] == ' ') {
      if (!w.empty()) out += std::string(first ? "" : ", ") + "\"" + w + "\"", first = false;
      w.clear();
    } else {
      w += words[i];
    }
  }
  return out + "]}";
}

}  // namespace

TEST_CASE("cli: batch writes each architecture's stats.json as separate renders do", "[cli][batch]") {
  const fs::path d = temp_dir("batch_same");
  const std::string common = "--frames 0:1 --resolution 24x24 --level analytic";
  {
    std::ofstream f(d / "archs.jsonl");
    for (const std::string& l : kLines) f << json_args(common, l) << "\n";
  }
  const Result b = run_oprt("batch " + scene("paper_polygons.json") + " --archs " + (d / "archs.jsonl").string() +
                            " --out " + (d / "batch").string() + " --threads 2");
  REQUIRE(b.status == 0);
  CHECK(b.output.find("oprt: batch: 5 renders, 0 refused or failed") != std::string::npos);
  for (std::size_t i = 0; i < kLines.size(); ++i) {
    INFO(kLines[i]);
    const fs::path alone = d / ("alone" + std::to_string(i));
    const Result r = run_oprt("render " + scene("paper_polygons.json") + " " + common + " " + kLines[i] +
                              " --no-progress --threads 2 --out " + alone.string());
    REQUIRE(r.status == 0);
    const fs::path mine = d / "batch" / std::to_string(i);
    CHECK(stats(mine, "status.json") == nlohmann::json{{"exit", 0}, {"message", ""}});
    const nlohmann::json x = without_wall_clock(stats(mine)), y = without_wall_clock(stats(alone));
    CHECK(x == y);
    CHECK(x["frames"].size() == 2);
    CHECK(bytes_of(mine / "stats.csv").size() > 100);
  }
}

TEST_CASE("cli: a batch line that render refuses is recorded, the others rendered", "[cli][batch]") {
  const fs::path d = temp_dir("batch_refused");
  {
    std::ofstream f(d / "archs.jsonl");
    f << "{\"args\": [\"--frames\", \"0\", \"--resolution\", \"8x8\", \"--accel\", \"octree\"]}\n";
    f << "{\"args\": [\"--frames\", \"0\", \"--resolution\", \"8x8\"], \"out\": \"" << (d / "mine").string() << "\"}\n";
  }
  const Result b = run_oprt("batch " + scene("paper_room.json") + " --archs " + (d / "archs.jsonl").string() + " --out " +
                            (d / "batch").string());
  REQUIRE(b.status == 0);
  const Result alone = run_oprt("render " + scene("paper_room.json") + " --frames 0 --resolution 8x8 --accel octree");
  CHECK(alone.status == 2);
  const nlohmann::json st = stats(d / "batch" / "0", "status.json");
  CHECK(st["exit"] == 2);
  CHECK(alone.output.find(st["message"].get<std::string>()) != std::string::npos);  // render's own message
  CHECK(stats(d / "mine", "status.json")["exit"] == 0);  // the line's own "out"
  CHECK(stats(d / "mine")["frames"].size() == 1);
}

TEST_CASE("cli: a bad batch file or a timed level is refused before anything renders", "[cli][batch]") {
  const fs::path d = temp_dir("batch_bad");
  {
    std::ofstream f(d / "bad.jsonl");
    f << "{\"args\": [\"--ius\", \"4\"]}\n{\"args\": [\"--out\", \"x\"]}\n";
    std::ofstream g(d / "at.jsonl");
    g << "{\"args\": [\"--level\", \"at\", \"--resolution\", \"8x8\", \"--frames\", \"0\"]}\n";
  }
  const Result bad = run_oprt("batch " + scene("paper_room.json") + " --archs " + (d / "bad.jsonl").string() + " --out " +
                              (d / "o1").string());
  CHECK(bad.status == 2);
  CHECK(bad.output.find((d / "bad.jsonl").string() + ": line 2: --out: the batch chooses") != std::string::npos);
  CHECK(!fs::exists(d / "o1"));
  const Result at = run_oprt("batch " + scene("paper_room.json") + " --archs " + (d / "at.jsonl").string() + " --out " +
                             (d / "o2").string());
  CHECK(at.status == 0);
  const nlohmann::json st = stats(d / "o2" / "0", "status.json");
  CHECK(st["exit"] == 2);
  CHECK(st["message"].get<std::string>().find("analytic level only") != std::string::npos);
  CHECK(!fs::exists(d / "o2" / "0" / "stats.json"));
}
