// The glTF loader against tests/data/gltf (made by make_gltf.py, whose docstring describes the
// scene): world positions computed by hand, animation at keys and between them, camera, lights,
// and one malformed variant per kind of error, each expected to name its JSON path.
#include "base/error.h"
#include "scene/gltf_motion.h"
#include "scene/load.h"

#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <sstream>

#include <unistd.h>

using namespace oprt;
using nlohmann::json;

namespace {
const std::string kDir = std::string(OPRT_SOURCE_DIR) + "/tests/data/gltf/";
const double kS45 = std::sqrt(0.5);

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// A file in the temporary directory, unique per process (ctest runs cases in parallel).
struct TempFile {
  std::string path;
  TempFile(const std::string& bytes, const std::string& ext) {
    static int n = 0;
    path = (std::filesystem::temp_directory_path() /
            ("oprt_gltf_test_" + std::to_string(::getpid()) + "_" + std::to_string(n++) + ext))
               .string();
    std::ofstream(path, std::ios::binary) << bytes;
  }
  ~TempFile() { std::remove(path.c_str()); }
};

const char* kB64 = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
std::string b64_encode(const std::string& in) {
  std::string out;
  std::size_t i = 0;
  for (; i + 2 < in.size(); i += 3) {
    const unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8 | (unsigned char)in[i + 2];
    for (int k = 3; k >= 0; --k) out += kB64[(v >> (6 * k)) & 63];
  }
  if (i + 1 == in.size()) {
    const unsigned v = (unsigned char)in[i] << 16;
    out += kB64[v >> 18], out += kB64[(v >> 12) & 63], out += "==";
  } else if (i + 2 == in.size()) {
    const unsigned v = (unsigned char)in[i] << 16 | (unsigned char)in[i + 1] << 8;
    out += kB64[v >> 18], out += kB64[(v >> 12) & 63], out += kB64[(v >> 6) & 63], out += "=";
  }
  return out;
}
std::string b64_decode(const std::string& in) {
  std::string out;
  unsigned acc = 0;
  int bits = 0;
  for (char c : in) {
    const char* p = std::strchr(kB64, c);
    if (c == '=' || !p) break;
    acc = acc << 6 | unsigned(p - kB64);
    bits += 6;
    if (bits >= 8) bits -= 8, out += char((acc >> bits) & 0xFF);
  }
  return out;
}

json base_doc() { return json::parse(slurp(kDir + "hierarchy.gltf")); }

std::string buffer_bytes(const json& doc) {
  const std::string uri = doc["buffers"][0]["uri"];
  return b64_decode(uri.substr(uri.find(",") + 1));
}
void set_buffer_bytes(json& doc, const std::string& bytes) {
  doc["buffers"][0]["uri"] = "data:application/octet-stream;base64," + b64_encode(bytes);
}
// Overwrites float component c of element e of accessor a in the embedded buffer.
void poke_float(json& doc, int a, int e, int c, float value) {
  const json& acc = doc["accessors"][a];
  const int width = acc["type"] == "SCALAR" ? 1 : acc["type"] == "VEC3" ? 3 : 4;
  const std::size_t at = doc["bufferViews"][acc["bufferView"].get<int>()]["byteOffset"].get<std::size_t>() +
                         (e * width + c) * 4;
  std::string bytes = buffer_bytes(doc);
  std::memcpy(&bytes[at], &value, 4);
  set_buffer_bytes(doc, bytes);
}

std::string u32(std::uint32_t v) { return std::string{char(v), char(v >> 8), char(v >> 16), char(v >> 24)}; }
std::string glb(const std::string& json_text, const std::string& bin, bool with_bin = true) {
  std::string j = json_text;
  while (j.size() % 4) j += ' ';
  std::string body = u32(j.size()) + u32(0x4E4F534A) + j;
  if (with_bin) body += u32(bin.size()) + u32(0x004E4942) + bin;
  return "glTF" + u32(2) + u32(12 + body.size()) + body;
}
json glb_doc(json doc) {
  doc["buffers"][0].erase("uri");
  return doc;
}

Scene load_text(const std::string& text, const std::string& ext = ".gltf") {
  TempFile f(text, ext);
  return load_scene(f.path);
}
Scene load_doc(const json& doc) { return load_text(doc.dump()); }

// Loading must fail with an InputError naming the file, a place containing `place` and a
// problem containing `problem`.
void expect_error_text(const std::string& text, const std::string& ext, const std::string& place,
                       const std::string& problem) {
  TempFile f(text, ext);
  try {
    load_scene(f.path);
    FAIL("no error (expected " << place << ": " << problem << ")");
  } catch (const InputError& e) {
    INFO(e.what());
    CHECK(e.file() == f.path);
    CHECK(e.place().find(place) != std::string::npos);
    CHECK(e.problem().find(problem) != std::string::npos);
  }
}
void expect_error(const std::function<void(json&)>& change, const std::string& place, const std::string& problem) {
  json doc = base_doc();
  change(doc);
  expect_error_text(doc.dump(), ".gltf", place, problem);
}

const Object& object(const Scene& s, const std::string& name) {
  for (const Object& o : s.objects)
    if (o.name == name) return o;
  FAIL("no object " << name);
  throw;
}

void check_point(const Vec3d& got, const Vec3d& want) {
  INFO("got (" << got.x << ", " << got.y << ", " << got.z << "), want (" << want.x << ", " << want.y << ", " << want.z << ")");
  CHECK(got.x == Approx(want.x).margin(1e-6));
  CHECK(got.y == Approx(want.y).margin(1e-6));
  CHECK(got.z == Approx(want.z).margin(1e-6));
}
Vec3d at(const Object& o, double frame, const Vec3d& local) { return o.motion->at(frame).point(local); }

bool has_note(const Scene& s, const std::string& text) {
  for (const auto& n : s.notes)
    if (n.find(text) != std::string::npos) return true;
  return false;
}
}  // namespace

TEST_CASE("gltf: node hierarchy gives hand-computed world positions", "[gltf]") {
  const Scene s = load_scene(kDir + "hierarchy.gltf");
  REQUIRE(s.objects.size() == 6);
  CHECK(s.triangle_count() == 16);
  // The cube's primitives split by material: +-X and +-Z red (8 triangles), +-Y blue (4).
  const Object& red = object(s, "box/red");
  const Object& blue = object(s, "box/blue");
  CHECK(red.mesh.triangles.size() == 8);
  CHECK(blue.mesh.triangles.size() == 4);
  CHECK(red.mesh.vertices.size() == 8);
  CHECK(red.motion == blue.motion);  // one rigid body
  CHECK_FALSE(red.motion->animated());
  // root = T(1,0,0) Rz(90) S(2); box = T(0,1,0).
  // (0.5,0.5,0.5) -> (0.5,1.5,0.5) -> (1,3,1) -> (-3,1,1) -> (-2,1,1).
  check_point(at(red, 0, {0.5, 0.5, 0.5}), {-2, 1, 1});
  // (-0.5,-0.5,-0.5) -> (-0.5,0.5,-0.5) -> (-1,1,-1) -> (-1,-1,-1) -> (0,-1,-1).
  check_point(at(blue, 7, {-0.5, -0.5, -0.5}), {0, -1, -1});
  // tri = matrix S(0.5,1,1) then T(0,0,-3), under root.
  const Object& tri = object(s, "tri");
  REQUIRE(tri.mesh.vertices.size() == 3);  // non-indexed: the vertices in order
  check_point(at(tri, 0, tri.mesh.vertices[0]), {1, 0, -6});
  check_point(at(tri, 0, tri.mesh.vertices[1]), {1, 1, -6});
  check_point(at(tri, 0, tri.mesh.vertices[2]), {-1, 0, -6});
  // Materials: metallic-roughness factors mapped to Phong.
  const Material& mr = s.materials[red.material];
  CHECK(mr.name == "red");
  check_point(mr.diffuse, {0.8, 0.1, 0.1});
  check_point(mr.specular, {0.1, 0.1, 0.1});  // 0.2 (1 - roughness 0.5)
  CHECK(mr.shininess == Approx(30));          // a = 0.25: 2 / a^2 - 2
  const Material& mb = s.materials[blue.material];
  check_point(mb.diffuse, {0.05, 0.1, 0.45});  // metallic 1: half the base colour
  check_point(mb.specular, {0.07, 0.14, 0.63});  // base (1 - 0.3)
  CHECK(mb.shininess == Approx(2 / (0.09 * 0.09) - 2));
  CHECK(s.materials[tri.material].name == "default");
  // The LINES primitive is skipped, said once although four nodes use the mesh.
  CHECK(has_note(s, "LINES primitive /meshes/1/primitives/1 skipped"));
  CHECK_FALSE(has_note(s, "more like it"));
}

TEST_CASE("gltf: LINEAR translation and rotation at keys and halfway", "[gltf]") {
  const Scene s = load_scene(kDir + "hierarchy.gltf");
  CHECK(s.frame_count == 61);  // last key at 2 s, 30 frames per second
  const Object& o = object(s, "spinner");
  CHECK(o.motion->animated());
  // Keys: T (0,-2,0) (2,-2,0) (2,-2,0); R 0, 90, 180 degrees about Y at 0, 1, 2 s.
  // Ry(a) (1,0,0) = (cos a, 0, -sin a).
  check_point(at(o, 0, {1, 0, 0}), {1, -2, 0});
  check_point(at(o, 15, {1, 0, 0}), {1 + kS45, -2, -kS45});  // halfway: T (1,-2,0), slerp 45 degrees
  check_point(at(o, 30, {1, 0, 0}), {2, -2, -1});
  // 90 -> 180 written as (0,-1,0,0): the short way passes 135 degrees, not 90 - 135.
  check_point(at(o, 45, {1, 0, 0}), {2 - kS45, -2, -kS45});
  check_point(at(o, 60, {1, 0, 0}), {1, -2, 0});
  // Outside the keys the motion clamps.
  check_point(at(o, 100, {1, 0, 0}), {1, -2, 0});
  check_point(at(o, -5, {1, 0, 0}), {1, -2, 0});
  // Slerp keeps the rotation rigid between keys.
  const Vec3d v = o.motion->at(7.3).vector({1, 0, 0});
  CHECK(std::sqrt(dot3(v, v)) == Approx(1));
}

TEST_CASE("gltf: STEP translation holds until the next key", "[gltf]") {
  const Scene s = load_scene(kDir + "hierarchy.gltf");
  const Object& o = object(s, "stepper");
  check_point(at(o, 0, {0, 0, 0}), {3, 0, 0});
  check_point(at(o, 14, {0, 0, 0}), {3, 0, 0});
  check_point(at(o, 15, {0, 0, 0}), {3, 1, 0});  // key at 0.5 s
  check_point(at(o, 29.9, {0, 0, 0}), {3, 1, 0});
  check_point(at(o, 30, {0, 0, 0}), {3, 2, 0});
  check_point(at(o, 60, {0, 0, 0}), {3, 2, 0});
}

TEST_CASE("gltf: CUBICSPLINE translation follows the Hermite curve", "[gltf]") {
  const Scene s = load_scene(kDir + "hierarchy.gltf");
  const Object& o = object(s, "cubic");
  check_point(at(o, 0, {0, 0, 0}), {-1, 2, 0});
  // s = 0.5: h00 p0 + h10 m0 + h01 p1 + h11 m1 = 0.5 (-1) + 0.125 (3) + 0.5 (0) - 0.125 (0).
  check_point(at(o, 15, {0, 0, 0}), {-0.125, 2, 0});
  check_point(at(o, 30, {0, 0, 0}), {0, 2, 0});
}

TEST_CASE("gltf: samplers clamp outside their keys", "[gltf]") {
  GltfSampler s;
  s.interpolation = GltfSampler::Interpolation::linear;
  s.width = 3;
  s.times = {1, 3};
  s.values = {0, 0, 0, 4, 8, 0};
  double v[3];
  s.evaluate(0, v);
  CHECK(v[0] == 0);
  s.evaluate(2, v);
  CHECK(v[0] == 2);
  CHECK(v[1] == 4);
  s.evaluate(9, v);
  CHECK(v[1] == 8);
}

TEST_CASE("gltf: the camera rides its node", "[gltf]") {
  const Scene s = load_scene(kDir + "hierarchy.gltf");
  CHECK(s.width == 384);  // aspect ratio 1.5, 256 rows
  CHECK(s.height == 256);
  const Camera c = s.camera->at(0);
  check_point(c.eye, {2, 3, 12});
  // Rx(-10 degrees): -Z -> (0, -sin 10, -cos 10), +Y -> (0, cos 10, -sin 10).
  const double a = 10 * M_PI / 180;
  check_point(glm::normalize(c.target - c.eye), {0, -std::sin(a), -std::cos(a)});
  check_point(glm::normalize(c.up), {0, std::cos(a), -std::sin(a)});
  CHECK(c.fov_y_deg == Approx(0.8 * 180 / M_PI));
}

TEST_CASE("gltf: KHR point and spot lights become normalised point lights", "[gltf]") {
  const Scene s = load_scene(kDir + "hierarchy.gltf");
  REQUIRE(s.lights.size() == 2);
  check_point(s.lights[0].position, {3, 5, 4});
  check_point(s.lights[0].color, {1, 0.5, 0.5});  // intensity 20 is the brightest
  check_point(s.lights[1].position, {-3, 5, 4});
  check_point(s.lights[1].color, {0.5, 0.5, 0.5});  // intensity 10
  CHECK(has_note(s, "spot light"));
}

TEST_CASE("gltf: the binary file loads the same scene", "[gltf]") {
  const Scene a = load_scene(kDir + "hierarchy.gltf");
  const Scene b = load_scene(kDir + "hierarchy.glb");
  REQUIRE(a.objects.size() == b.objects.size());
  for (std::size_t i = 0; i < a.objects.size(); ++i) {
    CHECK(a.objects[i].name == b.objects[i].name);
    CHECK(a.objects[i].mesh.vertices == b.objects[i].mesh.vertices);
    CHECK(a.objects[i].mesh.triangles == b.objects[i].mesh.triangles);
    for (double f : {0.0, 12.5, 45.0})
      check_point(b.objects[i].motion->at(f).point({1, 2, 3}), a.objects[i].motion->at(f).point({1, 2, 3}));
  }
  CHECK(a.frame_count == b.frame_count);
  CHECK(a.lights.size() == b.lights.size());
}

TEST_CASE("gltf: skins are refused", "[gltf]") {
  try {
    load_scene(kDir + "skin.gltf");
    FAIL("loaded a skin");
  } catch (const InputError& e) {
    CHECK(e.place() == "/skins/0");
    CHECK(e.problem() == "skins are not supported: oprt models rigid objects");
  }
}

TEST_CASE("gltf: morph targets are refused", "[gltf]") {
  try {
    load_scene(kDir + "morph.gltf");
    FAIL("loaded a morph target");
  } catch (const InputError& e) {
    CHECK(e.place() == "/meshes/1/primitives/0/targets");
    CHECK(e.problem() == "morph targets are not supported: oprt models rigid objects");
  }
  expect_error([](json& d) { d["animations"][0]["channels"][0]["target"]["path"] = "weights"; },
               "/animations/0/channels/0/target/path", "morph target weights are not supported");
}

TEST_CASE("gltf: malformed JSON and unsupported versions", "[gltf][errors]") {
  const std::string text = slurp(kDir + "hierarchy.gltf");
  expect_error_text(text.substr(0, 200), ".gltf", "line", "malformed JSON");
  expect_error_text("[1, 2]", ".gltf", "/", "expected an object");
  expect_error([](json& d) { d.erase("asset"); }, "/", "missing required key \"asset\"");
  expect_error([](json& d) { d["asset"]["version"] = "1.0"; }, "/asset/version", "not supported");
  expect_error([](json& d) { d["extensionsRequired"] = {"KHR_draco_mesh_compression"}; }, "/extensionsRequired/0",
               "required extension \"KHR_draco_mesh_compression\" is not supported");
  expect_error([](json& d) { d["scene"] = 4; }, "/scene", "scene 4 does not exist");
  expect_error([](json& d) { d["scenes"][0]["nodes"] = {6, 7}; }, "/", "no triangle meshes");
}

TEST_CASE("gltf: bad buffers and accessors name their JSON path", "[gltf][errors]") {
  expect_error([](json& d) { d["buffers"][0]["uri"] = "missing.bin"; }, "/buffers/0/uri", "cannot open buffer file");
  expect_error([](json& d) { d["buffers"][0]["uri"] = "data:application/octet-stream;base64,AB@D"; }, "/buffers/0/uri",
               "invalid base64");
  expect_error([](json& d) { d["buffers"][0]["byteLength"] = 100000; }, "/buffers/0/byteLength", "holds 452 bytes");
  expect_error([](json& d) { d["buffers"][0].erase("uri"); }, "/buffers/0", "only a .glb");
  expect_error([](json& d) { d["bufferViews"][0]["byteLength"] = 1000; }, "/bufferViews/0", "runs past the end of buffer 0");
  expect_error([](json& d) { d["bufferViews"][0]["byteStride"] = 8; }, "/bufferViews/0/byteStride", "smaller than an element");
  expect_error([](json& d) { d["accessors"][0]["count"] = 100; }, "/accessors/0", "needs 1200 bytes of bufferView 0");
  expect_error([](json& d) { d["accessors"][0]["byteOffset"] = 4; }, "/accessors/0", "needs 100 bytes");
  expect_error([](json& d) { d["accessors"][0]["componentType"] = 5123; }, "/accessors/0",
               "expected FLOAT components, found UNSIGNED_SHORT (POSITION of /meshes/0/primitives/0)");
  expect_error([](json& d) { d["accessors"][0]["componentType"] = 42; }, "/accessors/0/componentType", "unknown componentType");
  expect_error([](json& d) { d["accessors"][0]["type"] = "VEC2"; }, "/accessors/0", "expected type VEC3, found VEC2");
  expect_error([](json& d) { d["accessors"][0]["bufferView"] = 99; }, "/accessors/0/bufferView", "bufferView 99 does not exist");
  expect_error([](json& d) { d["accessors"][0].erase("bufferView"); }, "/accessors/0", "no bufferView");
  expect_error([](json& d) { d["accessors"][0]["sparse"] = json::object(); }, "/accessors/0", "sparse accessors");
  expect_error([](json& d) { d["accessors"][1]["componentType"] = 5122; }, "/accessors/1", "indices must be UNSIGNED");
  // Accessor 0 (the cube's 8 corners) cut to 4: the indices reach past it.
  expect_error([](json& d) { d["accessors"][0]["count"] = 4; }, "/meshes/0/primitives/0/indices",
               "index 7 (element 2 of accessor 1) is out of range: POSITION has 4 vertices");
  expect_error([](json& d) { d["accessors"][1]["count"] = 11; }, "/meshes/0/primitives/0/indices", "multiple of 3");
  expect_error([](json& d) { d["meshes"][0]["primitives"][0]["attributes"].erase("POSITION"); },
               "/meshes/0/primitives/0/attributes", "missing required key \"POSITION\"");
  expect_error([](json& d) { poke_float(d, 0, 2, 1, std::numeric_limits<float>::quiet_NaN()); }, "/accessors/0",
               "element 2 has a NaN component");
  expect_error([](json& d) { poke_float(d, 4, 1, 0, std::numeric_limits<float>::infinity()); }, "/accessors/4",
               "element 1 has a infinite component");
}

TEST_CASE("gltf: bad nodes name their JSON path", "[gltf][errors]") {
  expect_error([](json& d) { d["nodes"][1]["mesh"] = 9; }, "/nodes/1/mesh", "mesh 9 does not exist (the file has 2)");
  expect_error([](json& d) { d["nodes"][0]["translation"] = {1, 2}; }, "/nodes/0/translation", "array of 3 numbers");
  expect_error([](json& d) { d["nodes"][0]["rotation"] = {0, 0, 0, 0}; }, "/nodes/0/rotation", "zero quaternion");
  expect_error([](json& d) { d["nodes"][0]["scale"] = {1, 0, 1}; }, "/nodes/0/scale", "zero component");
  expect_error([](json& d) { d["nodes"][2]["matrix"][0] = 0; }, "/nodes/2/matrix", "singular");
  expect_error([](json& d) { d["nodes"][2]["matrix"][3] = 1; }, "/nodes/2/matrix", "not an affine matrix");
  expect_error([](json& d) { d["nodes"][2]["translation"] = {0, 0, 0}; }, "/nodes/2", "both a matrix and");
  expect_error([](json& d) { d["nodes"][1]["children"] = {1}; }, "/nodes/1/children/0", "its own child");
  expect_error([](json& d) { d["nodes"][3]["children"] = {1}; }, "/nodes/3/children/0",
               "node 1 is a child of both node 0 and node 3");
  // A cycle through a scene root: the root is somebody's child.
  expect_error([](json& d) { d["nodes"][1]["children"] = {0}; }, "/scenes/0/nodes/0", "not a root node");
  // Infinity has no JSON spelling; 1e999 comes closest, and the parser refuses it.
  json d = base_doc();
  d["nodes"][0]["translation"][0] = 12345.5;
  std::string text = d.dump();
  REQUIRE(text.find("12345.5") != std::string::npos);
  text.replace(text.find("12345.5"), 7, "1e999");
  expect_error_text(text, ".gltf", "line 1", "number overflow parsing '1e999' (numbers must be finite)");
  expect_error([](json& d) { d["cameras"][0]["perspective"]["yfov"] = 0; }, "/cameras/0/perspective/yfov", "out of range");
  expect_error([](json& d) { d["cameras"][0]["type"] = "fisheye"; }, "/cameras/0/type", "unknown camera type");
  expect_error([](json& d) { d["extensions"]["KHR_lights_punctual"]["lights"][0]["type"] = "area"; },
               "/extensions/KHR_lights_punctual/lights/0/type", "unknown light type");
  expect_error([](json& d) { d["nodes"][7]["extensions"]["KHR_lights_punctual"]["light"] = 5; },
               "/nodes/7/extensions/KHR_lights_punctual/light", "light 5 does not exist");
}

TEST_CASE("gltf: bad animations name their JSON path", "[gltf][errors]") {
  expect_error([](json& d) { d["animations"][0]["samplers"][0]["interpolation"] = "BEZIER"; },
               "/animations/0/samplers/0/interpolation", "unknown interpolation");
  expect_error([](json& d) { d["animations"][0]["channels"][0]["target"]["path"] = "colour"; },
               "/animations/0/channels/0/target/path", "unknown animation path");
  expect_error([](json& d) { d["animations"][0]["channels"][0]["target"]["node"] = 2; },
               "/animations/0/channels/0/target/node", "node 2 has a matrix");
  expect_error([](json& d) { d["animations"][0]["channels"][0]["sampler"] = 7; }, "/animations/0/channels/0/sampler",
               "sampler 7 does not exist");
  // Cubic spline needs in-tangent, value and out-tangent per key: 6 values for 2 keys.
  expect_error([](json& d) { d["animations"][1]["samplers"][1]["output"] = 10; }, "/animations/1/samplers/1/output",
               "output has 3 values for 2 key times (CUBICSPLINE needs 6)");
  expect_error([](json& d) { d["animations"][0]["samplers"][1]["output"] = 7; }, "/accessors/7",
               "expected type VEC4, found VEC3");
  expect_error([](json& d) { poke_float(d, 6, 2, 0, 1); }, "/accessors/6",
               "key times must increase: element 2 (1) is not after 1");
  expect_error([](json& d) { poke_float(d, 7, 1, 0, std::numeric_limits<float>::quiet_NaN()); }, "/accessors/7",
               "element 1 has a NaN component (translation values of /animations/0/samplers/0");
  expect_error([](json& d) { for (int c = 0; c < 4; ++c) poke_float(d, 8, 1, c, 0); }, "/accessors/8",
               "rotation key 1 is a zero quaternion");
  expect_error(
      [](json& d) {
        d["animations"][0]["channels"][0]["target"]["path"] = "scale";
      },
      "/accessors/7", "scale key 0 has a zero component");
  expect_error([](json& d) { poke_float(d, 6, 2, 0, 1e9f); }, "/animations/0/samplers/0/input", "more than 1000000 frames");
}

TEST_CASE("gltf: malformed GLB containers are refused", "[gltf][errors]") {
  const json doc = base_doc();
  const std::string bin = buffer_bytes(doc);
  const std::string good = glb(glb_doc(doc).dump(), bin);
  CHECK(load_text(good, ".glb").objects.size() == 6);
  expect_error_text("glT", ".glb", "GLB header", "not a binary glTF");
  expect_error_text("glTF" + u32(2), ".glb", "GLB header", "too short");
  expect_error_text("{\"asset\": {}}", ".glb", "GLB header", "not a binary glTF");
  std::string v1 = good;
  v1[4] = 1;
  expect_error_text(v1, ".glb", "GLB header", "GLB version 1 is not supported");
  expect_error_text(good.substr(0, good.size() - 8), ".glb", "GLB header", "header gives a length of");
  std::string long_chunk = good;
  long_chunk[12] = char(0xFF), long_chunk[13] = char(0xFF);
  expect_error_text(long_chunk, ".glb", "GLB chunk 0", "runs past the end of the file");
  std::string bin_first = good;
  std::memcpy(&bin_first[16], u32(0x004E4942).data(), 4);
  expect_error_text(bin_first, ".glb", "GLB chunk 0", "the first chunk must be the JSON chunk");
  expect_error_text(glb(glb_doc(doc).dump(), bin, false), ".glb", "/buffers/0", "the .glb has none");
  expect_error_text(glb("{\"asset\": ", bin), ".glb", "line 1", "malformed JSON");
  // A GLB is recognised by its magic whatever its extension.
  CHECK(load_text(good, ".gltf").objects.size() == 6);
}

TEST_CASE("gltf: defaults without camera and lights", "[gltf]") {
  json d = base_doc();
  d["scenes"][0]["nodes"] = {0, 3, 4, 5};
  const Scene s = load_doc(d);
  CHECK(s.width == 256);
  CHECK(s.height == 256);
  REQUIRE(s.lights.size() == 1);
  check_point(s.lights[0].color, {1, 1, 1});
  CHECK(has_note(s, "no perspective camera"));
  CHECK(has_note(s, "no lights"));
  // The default camera looks down -Z at the centre of the frame-0 bounds, from far enough away
  // for the bounding sphere to fit the 45 degree view.
  const Camera c = s.camera->at(0);
  const Vec3d view = c.target - c.eye;
  CHECK(view.x == 0);
  CHECK(view.y == 0);
  CHECK(view.z < 0);
  CHECK(c.fov_y_deg == 45);
  // Every object at frame 0 lies within the view cone.
  const double half = glm::radians(c.fov_y_deg / 2);
  for (const Object& o : s.objects)
    for (const Vec3d& v : o.mesh.vertices) {
      const Vec3d w = at(o, 0, v) - c.eye;
      CHECK(std::atan2(std::fabs(w.y), -w.z) < half);
      CHECK(std::atan2(std::fabs(w.x), -w.z) < half);
    }
}

TEST_CASE("gltf: a directional light becomes a far point light", "[gltf]") {
  json d = base_doc();
  d["extensions"]["KHR_lights_punctual"]["lights"][0]["type"] = "directional";
  const Scene s = load_doc(d);
  // The lamp node is not rotated: it shines down -Z, so the stand-in sits far out along +Z.
  CHECK(s.lights[0].position.z > 1000);
  CHECK(std::fabs(s.lights[0].position.x) < 10);
  CHECK(has_note(s, "directional light"));
}

TEST_CASE("gltf: triangle strips and fans become triangle lists", "[gltf]") {
  // The +-X index list read as a strip or fan: windows with a repeated index are dropped.
  for (int mode : {5, 6}) {
    json d = base_doc();
    d["meshes"][0]["primitives"][0]["mode"] = mode;
    const Scene s = load_doc(d);
    CHECK(object(s, "box/red").mesh.triangles.size() == 8 + 4);
  }
}

TEST_CASE("gltf: two channels on one property: the first wins", "[gltf]") {
  json d = base_doc();
  d["animations"].push_back({{"samplers", {{{"input", 9}, {"output", 10}}}},
                             {"channels", {{{"sampler", 0}, {"target", {{"node", 3}, {"path", "translation"}}}}}}});
  const Scene s = load_doc(d);
  check_point(at(object(s, "spinner"), 15, {0, 0, 0}), {1, -2, 0});
  CHECK(has_note(s, "/animations/2/channels/0 drives the translation of node 3 already driven by /animations/0/channels/0"));
}

TEST_CASE("gltf: an external buffer file is found beside the scene", "[gltf]") {
  json d = base_doc();
  TempFile bin(buffer_bytes(d), " data.bin");  // a space: the URI spells it %20
  const std::string name = std::filesystem::path(bin.path).filename().string();
  d["buffers"][0]["uri"] = name.substr(0, name.find(' ')) + "%20data.bin";
  const Scene s = load_doc(d);
  CHECK(s.objects.size() == 6);
  d["buffers"][0]["uri"] = "http://example.com/data.bin";
  expect_error_text(d.dump(), ".gltf", "/buffers/0/uri", "only relative file paths and data URIs");
}

// ----------------------------------------------------------------------------------------
// Materials and vertex normals as published (issue 29, item 2)

namespace {
std::string floats(const std::vector<float>& v) {
  std::string out(v.size() * 4, '\0');
  std::memcpy(&out[0], v.data(), out.size());
  return out;
}

// One triangle drawn twice (with NORMAL, then without), and four materials: a perfect mirror,
// a glass with transmission and ior, a transmitting one without ior, a rough metal with an
// extension that is not mapped.
json whitted_doc() {
  const std::string bytes = floats({0, 0, 0, 1, 0, 0, 0, 1, 0}) + floats({0, 0, 2, 3, 4, 0, 0, 0, -1});
  json doc = {
      {"asset", {{"version", "2.0"}}},
      {"buffers", {{{"byteLength", 72}, {"uri", "data:application/octet-stream;base64," + b64_encode(bytes)}}}},
      {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 36}},
                       {{"buffer", 0}, {"byteOffset", 36}, {"byteLength", 36}}}},
      {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"type", "VEC3"}, {"count", 3},
                      {"min", {0, 0, 0}}, {"max", {1, 1, 0}}},
                     {{"bufferView", 1}, {"componentType", 5126}, {"type", "VEC3"}, {"count", 3}}}},
      {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"NORMAL", 1}}}, {"material", 0}},
                                   {{"attributes", {{"POSITION", 0}}}, {"material", 0}}}}}}},
      {"materials",
       {{{"name", "mirror"},
         {"pbrMetallicRoughness", {{"baseColorFactor", {0.9, 0.8, 0.7, 1}}, {"metallicFactor", 1}, {"roughnessFactor", 0}}}},
        {{"name", "glass"},
         {"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 0.75}}},
                         {"KHR_materials_ior", {{"ior", 1.33}}}}}},
        {{"name", "clear"}, {"extensions", {{"KHR_materials_transmission", {{"transmissionFactor", 1}}}}}},
        {{"name", "brushed"},
         {"pbrMetallicRoughness", {{"metallicFactor", 1}, {"roughnessFactor", 0.5}}},
         {"extensions", {{"KHR_materials_specular", json::object()}}}}}},
      {"nodes", {{{"mesh", 0}, {"scale", {2, 1, 1}}}}},
      {"scenes", {{{"nodes", {0}}}}},
      {"scene", 0}};
  return doc;
}
}  // namespace

TEST_CASE("gltf: a mirror, transmission and ior map to reflect, transmit and ior", "[gltf][materials]") {
  const Scene s = load_doc(whitted_doc());
  REQUIRE(s.materials.size() == 4);
  const Material &mirror = s.materials[0], &glass = s.materials[1], &clear = s.materials[2], &brushed = s.materials[3];
  CHECK(mirror.reflect == Vec3d(0.9, 0.8, 0.7));  // metallic 1, roughness 0: base colour
  CHECK_FALSE(mirror.transmits());
  CHECK(mirror.ior == 1);
  CHECK(mirror.diffuse == Vec3d(0.45, 0.4, 0.35));  // the Phong mapping as before: base (1 - 1/2)
  CHECK_FALSE(glass.reflects());  // glTF's defaults metallic 1, roughness 1: no mirror
  CHECK(glass.transmit == Vec3d(0.75));
  CHECK(glass.ior == 1.33);
  CHECK(clear.transmit == Vec3d(1));
  CHECK(clear.ior == 1.5);  // glTF's dielectric index without KHR_materials_ior
  CHECK_FALSE(brushed.reflects());  // roughness 0.5: not mapped
  CHECK(has_note(s, "material extensions other than KHR_materials_transmission and KHR_materials_ior are ignored"));
}

TEST_CASE("gltf: NORMAL is read per corner, made unit, in the mesh's own frame", "[gltf][normals]") {
  const Scene s = load_doc(whitted_doc());
  REQUIRE(s.objects.size() == 1);
  const Mesh& m = s.objects[0].mesh;
  REQUIRE(m.triangles.size() == 2);
  CHECK(m.vertices.size() == 3);  // both primitives share POSITION's vertices, as before
  REQUIRE(m.normal_index.size() == 2);
  CHECK(m.triangles_with_normals() == 1);  // the primitive without NORMAL is flat
  CHECK_FALSE(m.has_normals(1));
  // (0, 0, 2), (3, 4, 0), (0, 0, -1) made unit; the node's scale (2, 1, 1) is its motion and
  // leaves the local normals alone.
  CHECK(m.normals[m.normal_index[0][0]] == Vec3d(0, 0, 1));
  CHECK(m.normals[m.normal_index[0][1]] == Vec3d(0.6, 0.8, 0));
  CHECK(m.normals[m.normal_index[0][2]] == Vec3d(0, 0, -1));
  CHECK(has_note(s, "vertex normals (NORMAL) read"));
  CHECK(has_note(s, "interpolated for the lights' terms"));
}

TEST_CASE("gltf: bad transmission, ior and NORMAL name their JSON path", "[gltf][materials][errors]") {
  auto expect = [](const std::function<void(json&)>& change, const std::string& place, const std::string& problem) {
    json doc = whitted_doc();
    change(doc);
    expect_error_text(doc.dump(), ".gltf", place, problem);
  };
  expect([](json& d) { d["materials"][1]["extensions"]["KHR_materials_ior"]["ior"] = 0.5; },
         "/materials/1/extensions/KHR_materials_ior/ior", "out of range");
  expect([](json& d) { d["materials"][2]["extensions"]["KHR_materials_transmission"]["transmissionFactor"] = 2; },
         "/materials/2/extensions/KHR_materials_transmission/transmissionFactor", "out of range");
  expect([](json& d) { d["accessors"][1]["count"] = 2; }, "/meshes/0/primitives/0/attributes/NORMAL",
         "a normal per vertex");
  expect([](json& d) { d["accessors"][1]["type"] = "VEC4"; d["accessors"][1]["count"] = 2; }, "/accessors/1",
         "expected type VEC3");
}

TEST_CASE("gltf: CUBICSPLINE tangents are per second, scaled by the keys' interval", "[gltf]") {
  // Keys 2 s apart, both values 0, the first key's out-tangent 1 per second, the second's
  // in-tangent 0. Halfway (s = 0.5): h10 (s) = s^3 - 2 s^2 + s = 0.125, times dt = 2 s times
  // the tangent 1: 0.25. (Unscaled, the tangent would give 0.125.)
  GltfSampler c;
  c.interpolation = GltfSampler::Interpolation::cubic_spline;
  c.width = 3;
  c.times = {0, 2};
  c.values = {0, 0, 0, 0, 0, 0, 1, 0, 0,   // key 0: in-tangent, value, out-tangent
              0, 0, 0, 0, 0, 0, 0, 0, 0};  // key 1
  double v[3];
  c.evaluate(1, v);
  CHECK(v[0] == Approx(0.25));
  CHECK(v[1] == 0);
  // A quarter of the way (s = 0.25): h10 = 0.015625 - 0.125 + 0.25 = 0.140625, times 2.
  c.evaluate(0.5, v);
  CHECK(v[0] == Approx(0.28125));
}

TEST_CASE("gltf: a node's non-uniform scale applies before its rotation (T R S)", "[gltf]") {
  // Scale (2, 1, 1), 90 degrees about z, then +(0, 0, 5): (1,0,0) -> (2,0,0) -> (0,2,0) -> (0,2,5);
  // (0,1,0) -> (0,1,0) -> (-1,0,0) -> (-1,0,5). Rotating first would give (0,1,5) and (-2,0,5).
  const Affine<double> m = trs_affine({0, 0, 5}, axis_angle({0, 0, 1}, 90), {2, 1, 1});
  const Vec3d a = m.point({1, 0, 0}), b = m.point({0, 1, 0});
  CHECK(a.x == Approx(0).margin(1e-12));
  CHECK(a.y == Approx(2));
  CHECK(a.z == Approx(5));
  CHECK(b.x == Approx(-1));
  CHECK(b.y == Approx(0).margin(1e-12));
  CHECK(b.z == Approx(5));
}
