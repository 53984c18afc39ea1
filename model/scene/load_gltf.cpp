// glTF 2.0 (.gltf with embedded or external buffers, .glb) as an oprt scene of rigid objects.
//
// Read with nlohmann::json through JsonIn rather than tinygltf: tinygltf skips values of the
// wrong type silently and reports problems as free text without the JSON path, while every
// oprt loader error must name the place (/accessors/3). What tinygltf would add beyond the
// JSON -- the GLB container, base64 data URIs, external .bin files -- is a few dozen lines.
//
// What becomes what (docs/gltf.md repeats this for users):
// - Scene: the document's "scene", else scenes[0]; a file without scenes uses every root node.
// - Objects: each node with a mesh, one Object per material used by its primitives (the
//   primitives of one material merged), in the node's local coordinates; its motion is the
//   product of the local transforms from the root down to the node. TRIANGLES, TRIANGLE_STRIP
//   and TRIANGLE_FAN primitives are read (strips and fans as triangle lists, dropping the
//   degenerate joints); POINTS and LINES* are skipped with a note. POSITION must be float VEC3.
// - Animation: translation / rotation / scale channels, STEP, LINEAR (rotation: slerp, shortest
//   arc) and CUBICSPLINE (Hermite). Every animation plays at once from t = 0; if two channels
//   drive the same node property the first (lowest animation, then channel index) wins and a
//   note names the other. Frame f is time f / 30 s; frame_count covers the last key.
// - Camera: the first perspective camera met walking the scene (depth first, in order); eye at
//   the node origin, looking down -Z, up +Y, moving with the node's animated chain; yfov ->
//   fov_y_deg; the image is 256 rows high and round(256 * aspectRatio) wide (256 x 256 without
//   an aspect ratio). No camera: a default one (45 degrees) looks down -Z at the bounds of the
//   whole animation (every object at every frame: scene_bounds).
// - Lights (KHR_lights_punctual): point lights at their node's position, following the node
//   frame by frame when it is animated; spot lights as point lights; directional lights as a
//   point light 1000 scene radii away against their node's -Z (turning with it). oprt lights
//   do not fall off with distance, so intensities are relative: colour = colour * intensity /
//   (largest intensity in the scene). No light: one white light near the camera.
// - Buffers: a base64 data URI, a relative file name (percent-encoded) beside the .gltf, or the
//   GLB's binary chunk; anything else at a uri is an InputError there. Images are never opened
//   (textures are ignored), so an image uri cannot fail.
// - Materials: pbrMetallicRoughness factors (textures ignored) mapped to Phong as
//   diffuse = base (1 - metallic / 2), specular = mix(0.2, base, metallic) (1 - roughness),
//   shininess = 2 / a^2 - 2 with a = roughness^2 (the Blinn-Phong <-> GGX correspondence),
//   clamped to [1, 1000]. Primitives without a material get oprt's default material.
//   Whitted terms (traced as reflection and refraction rays): metallic 1 with roughness 0 is a mirror, reflect =
//   base; KHR_materials_transmission's transmissionFactor -> transmit; KHR_materials_ior's ior
//   -> ior (default 1.5 for a transmitting material, glTF's dielectric index; 1 otherwise).
//   Not mapped: textures, roughness between 0 and 1 (no glossy reflection), partial
//   metallic, KHR_materials_specular, _volume, _clearcoat and the others (one note).
// - Vertex normals: NORMAL, unit length after normalising, per triangle corner (scene.h);
//   primitives without NORMAL have flat triangles.
// - Refused with an InputError: skins, morph targets (and weight animation), sparse accessors,
//   accessors without a buffer view, required extensions other than KHR_lights_punctual,
//   KHR_materials_* and KHR_texture_*.
#include "scene/gltf_motion.h"
#include "scene/json_vec.h"
#include "scene/load.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>

namespace oprt {

namespace {

constexpr int kImageRows = 256;
constexpr long long kMaxFrames = 1000000;
constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

enum Component : int { kByte = 5120, kUByte = 5121, kShort = 5122, kUShort = 5123, kUInt = 5125, kFloat = 5126 };

int component_size(long long c) {
  switch (c) {
    case kByte: case kUByte: return 1;
    case kShort: case kUShort: return 2;
    case kUInt: case kFloat: return 4;
    default: return 0;
  }
}

const char* component_name(long long c) {
  switch (c) {
    case kByte: return "BYTE";
    case kUByte: return "UNSIGNED_BYTE";
    case kShort: return "SHORT";
    case kUShort: return "UNSIGNED_SHORT";
    case kUInt: return "UNSIGNED_INT";
    case kFloat: return "FLOAT";
    default: return "?";
  }
}

int type_width(const std::string& t) {
  if (t == "SCALAR") return 1;
  if (t == "VEC2") return 2;
  if (t == "VEC3") return 3;
  if (t == "VEC4") return 4;
  if (t == "MAT2") return 4;
  if (t == "MAT3") return 9;
  if (t == "MAT4") return 16;
  return 0;
}

std::string number_text(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

std::uint32_t read_u32(const std::uint8_t* p) {
  return std::uint32_t(p[0]) | std::uint32_t(p[1]) << 8 | std::uint32_t(p[2]) << 16 | std::uint32_t(p[3]) << 24;
}

// A component of an accessor element as a double; normalised integers map to [-1, 1] / [0, 1]
// as the glTF spec says (signed: max(c / MAX, -1)).
double read_component(const std::uint8_t* p, long long type, bool normalized) {
  switch (type) {
    case kFloat: { float f; std::memcpy(&f, p, 4); return f; }
    case kUInt: return read_u32(p);
    case kUShort: { const double v = std::uint16_t(p[0] | p[1] << 8); return normalized ? v / 65535.0 : v; }
    case kShort: { const double v = std::int16_t(std::uint16_t(p[0] | p[1] << 8)); return normalized ? std::max(v / 32767.0, -1.0) : v; }
    case kUByte: { const double v = p[0]; return normalized ? v / 255.0 : v; }
    case kByte: { const double v = std::int8_t(p[0]); return normalized ? std::max(v / 127.0, -1.0) : v; }
    default: return 0;
  }
}

// RFC 4648 base64, standard alphabet; padding optional; anything else is an error (returns false).
bool decode_base64(const std::string& s, std::size_t from, std::vector<std::uint8_t>& out, std::size_t& bad) {
  std::uint32_t acc = 0;
  int bits = 0;
  std::size_t end = s.size();
  while (end > from && s[end - 1] == '=') --end;
  out.reserve((end - from) * 3 / 4);
  for (std::size_t i = from; i < end; ++i) {
    const char c = s[i];
    int v;
    if (c >= 'A' && c <= 'Z') v = c - 'A';
    else if (c >= 'a' && c <= 'z') v = c - 'a' + 26;
    else if (c >= '0' && c <= '9') v = c - '0' + 52;
    else if (c == '+') v = 62;
    else if (c == '/') v = 63;
    else { bad = i; return false; }
    acc = (acc << 6) | static_cast<std::uint32_t>(v);
    bits += 6;
    if (bits >= 8) {
      bits -= 8;
      out.push_back(static_cast<std::uint8_t>((acc >> bits) & 0xFF));
    }
  }
  return true;
}

std::string percent_decode(const std::string& s) {
  std::string out;
  for (std::size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size() && std::isxdigit(static_cast<unsigned char>(s[i + 1])) &&
        std::isxdigit(static_cast<unsigned char>(s[i + 2]))) {
      out += static_cast<char>(std::stoi(s.substr(i + 1, 2), nullptr, 16));
      i += 2;
    } else {
      out += s[i];
    }
  }
  return out;
}

// A string for a message, in quotes, cut to its first 60 bytes (and its length, when longer),
// control bytes written as \xNN.
std::string quoted_start(const std::string& s) {
  std::string out = "\"";
  for (std::size_t i = 0; i < s.size() && i < 60; ++i) {
    const auto c = static_cast<unsigned char>(s[i]);
    if (c < 0x20 || c == 0x7F) {
      static const char* hex = "0123456789ABCDEF";
      out += std::string("\\x") + hex[c >> 4] + hex[c & 15];
    } else {
      out += s[i];
    }
  }
  if (s.size() <= 60) return out + "\"";
  return out + "...\" (" + std::to_string(s.size()) + " characters)";
}

bool read_file_bytes(const std::string& path, std::vector<std::uint8_t>& out) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return false;
  out.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  return !in.bad();
}

// The Phong terms from the metallic-roughness factors; the Whitted terms (reflect, transmit,
// ior) are set by read_materials.
Material pbr_to_phong(const std::string& name, const Vec3d& base, double metallic, double roughness) {
  Material m;
  m.name = name;
  m.diffuse = base * (1 - 0.5 * metallic);
  m.specular = (Vec3d(0.2) * (1 - metallic) + base * metallic) * (1 - roughness);
  const double a = roughness * roughness;
  m.shininess = a > 0 ? std::clamp(2 / (a * a) - 2, 1.0, 1000.0) : 1000.0;
  return m;
}

// Notes said once per kind: the first occurrence, and how many more there were.
class Notes {
 public:
  void add(const std::string& kind, const std::string& text) {
    for (auto& e : entries_)
      if (e.kind == kind) { ++e.more; return; }
    entries_.push_back({kind, text, 0});
  }
  std::vector<std::string> lines() const {
    std::vector<std::string> out;
    for (const auto& e : entries_)
      out.push_back(e.more ? e.text + " (and " + std::to_string(e.more) + " more like it)" : e.text);
    return out;
  }

 private:
  struct Entry { std::string kind, text; int more; };
  std::vector<Entry> entries_;
};

struct Accessor {
  std::string place;  // /accessors/i
  long long component = 0;
  int width = 0;       // components per element
  long long count = 0;
  bool normalized = false;
  const std::uint8_t* data = nullptr;  // first element
  std::size_t stride = 0;
};

struct LightSource {
  std::string type;
  Vec3d color{1};
  double intensity = 1;
  Vec3d position{0}, direction{0, 0, -1};  // at frame 0
  MotionPtr node;  // the node's motion when it is animated, else null
};

class GltfReader {
 public:
  explicit GltfReader(const std::string& path) : file_(path) {}
  Scene read();

 private:
  // ---- container and references
  void parse_container();
  std::vector<JsonIn> list(const char* name) const {
    auto a = root().find(name);
    return a ? a->items() : std::vector<JsonIn>{};
  }
  JsonIn root() const { return JsonIn(doc_, file_); }
  std::size_t ref(const JsonIn& v, const std::vector<JsonIn>& target, const char* what) const {
    const long long i = v.integer(0, std::numeric_limits<std::uint32_t>::max());
    if (static_cast<std::size_t>(i) >= target.size())
      v.fail(std::string(what) + " " + std::to_string(i) + " does not exist (the file has " +
             std::to_string(target.size()) + ")");
    return static_cast<std::size_t>(i);
  }

  // ---- binary data
  const std::vector<std::uint8_t>& buffer(std::size_t i);
  void read_uri(const JsonIn& uri, std::vector<std::uint8_t>& out) const;
  Accessor accessor(std::size_t i, const std::string& use);
  std::vector<double> read_floats(std::size_t i, int width, bool allow_normalized, const std::string& use);
  std::vector<std::uint32_t> read_indices(std::size_t i, const std::string& use);

  // ---- document parts
  void refuse_deformation();
  void read_materials();
  void read_animations();
  GltfSamplerPtr read_sampler(const JsonIn& sampler, const std::string& path, const JsonIn& channel_path);
  const GltfLocal& local(std::size_t node);
  std::vector<std::size_t> scene_nodes();  // depth-first, parents before children
  std::vector<GltfLocal> chain(std::size_t node);
  // A mesh's triangles, one group per material in order of first use (read once per mesh,
  // however many nodes instance it).
  struct Group {
    std::uint32_t material;
    Mesh mesh;
    std::map<std::size_t, std::vector<std::uint32_t>> remap;  // POSITION accessor -> mesh vertex
    std::map<std::size_t, std::vector<std::uint32_t>> nremap;  // NORMAL accessor -> mesh normal
  };
  const std::vector<Group>& mesh_groups(std::size_t mesh);
  void add_mesh_objects(std::size_t node, Scene& s);
  void add_camera(std::size_t node, Scene& s);
  void add_light(std::size_t node);
  void finish_lights_and_camera(Scene& s);

  std::string file_;
  nlohmann::json doc_;
  bool glb_ = false;
  std::vector<std::uint8_t> glb_bin_;
  bool glb_has_bin_ = false;
  std::vector<JsonIn> buffers_j_, views_j_, accessors_j_, meshes_j_, nodes_j_, materials_j_, cameras_j_,
      lights_j_;
  std::map<std::size_t, std::vector<std::uint8_t>> buffers_;
  std::vector<Material> materials_;
  std::map<std::size_t, std::vector<Group>> mesh_groups_;
  std::vector<std::optional<GltfLocal>> locals_;
  std::vector<std::size_t> parent_;  // kNone for a root
  // Channels by (node, "translation" | "rotation" | "scale").
  std::map<std::pair<std::size_t, std::string>, GltfSamplerPtr> channels_;
  std::map<std::pair<std::size_t, std::string>, std::string> channel_place_;
  double last_key_time_ = 0;
  std::string last_key_place_;
  std::uint32_t default_material_ = kNone;
  bool camera_found_ = false;
  bool normals_read_ = false;
  std::vector<LightSource> lights_;
  Notes notes_;
};

void GltfReader::parse_container() {
  require_regular_file(file_);
  std::vector<std::uint8_t> bytes;
  if (!read_file_bytes(file_, bytes)) throw InputError(file_, "", "cannot read file");
  // A binary glTF is recognised by its magic, whatever the extension says.
  glb_ = bytes.size() >= 4 && std::memcmp(bytes.data(), "glTF", 4) == 0;
  const bool says_glb = std::filesystem::path(file_).extension() == ".glb";
  if (!glb_ && says_glb)
    throw InputError(file_, "GLB header", "not a binary glTF file (it does not start with \"glTF\")");
  if (!glb_) {
    doc_ = JsonIn::parse_text(std::string(bytes.begin(), bytes.end()), file_);
    return;
  }
  if (bytes.size() < 12)
    throw InputError(file_, "GLB header", "file is too short for a GLB header (" + std::to_string(bytes.size()) + " bytes)");
  const std::uint32_t version = read_u32(&bytes[4]);
  if (version != 2)
    throw InputError(file_, "GLB header", "GLB version " + std::to_string(version) + " is not supported (expected 2)");
  const std::uint32_t length = read_u32(&bytes[8]);
  if (length > bytes.size())
    throw InputError(file_, "GLB header", "header gives a length of " + std::to_string(length) +
                                              " bytes but the file has " + std::to_string(bytes.size()));
  if (length < 20) throw InputError(file_, "GLB header", "the file has no JSON chunk");
  std::size_t at = 12;
  bool have_json = false;
  for (int chunk = 0; at < length; ++chunk) {
    const std::string place = "GLB chunk " + std::to_string(chunk);
    if (length - at < 8) throw InputError(file_, place, "chunk header runs past the end of the file");
    const std::uint32_t size = read_u32(&bytes[at]);
    const std::uint32_t type = read_u32(&bytes[at + 4]);
    at += 8;
    if (size > length - at)
      throw InputError(file_, place, "chunk of " + std::to_string(size) + " bytes runs past the end of the file (" +
                                         std::to_string(length - at) + " bytes left)");
    if (chunk == 0) {
      if (type != 0x4E4F534Au) throw InputError(file_, place, "the first chunk must be the JSON chunk");
      std::string text(bytes.begin() + at, bytes.begin() + at + size);
      while (!text.empty() && text.back() == '\0') text.pop_back();  // some writers pad with zeros
      doc_ = JsonIn::parse_text(text, file_);
      have_json = true;
    } else if (type == 0x004E4942u && !glb_has_bin_) {
      glb_bin_.assign(bytes.begin() + at, bytes.begin() + at + size);
      glb_has_bin_ = true;
    }  // other chunk types: ignored, as the spec asks
    at += size;
  }
  if (!have_json) throw InputError(file_, "GLB header", "the file has no JSON chunk");
}

// A buffer's uri: a base64 data URI, or a file name relative to the .gltf (percent-encoded).
// Whatever else it holds -- a mangled data prefix, a name longer than any file system takes,
// a NUL byte -- ends in an InputError at the uri's place, never in an exception of the file
// system library (whose message would echo the whole string).
void GltfReader::read_uri(const JsonIn& u, std::vector<std::uint8_t>& out) const {
  namespace fs = std::filesystem;
  const std::string uri = u.string();
  if (uri.rfind("data:", 0) == 0) {
    const auto comma = uri.find(";base64,");
    if (comma == std::string::npos) u.fail("only base64 data URIs are supported (no \";base64,\" after \"data:\")");
    std::size_t bad = 0;
    if (!decode_base64(uri, comma + 8, out, bad))
      u.fail("invalid base64 character at position " + std::to_string(bad) + " of the data URI");
    return;
  }
  if (uri.empty()) u.fail("the uri is empty: neither a data URI nor a file name");
  if (uri.find("://") != std::string::npos) u.fail("only relative file paths and data URIs are supported");
  const std::string name = percent_decode(uri);
  const std::string shown = quoted_start(name);
  if (name.find('\0') != std::string::npos) u.fail("the file name " + shown + " contains a NUL byte");
  // Linux's limits: 255 bytes a path component, 4,096 a path (PATH_MAX). Refused here, they
  // cannot be a file name; under them the file system answers with an error code.
  constexpr std::size_t kMaxName = 255, kMaxPath = 4096;
  for (const fs::path& part : fs::path(name))
    if (part.native().size() > kMaxName)
      u.fail("neither a data URI nor a usable file name: " + shown + " has a part of " +
             std::to_string(part.native().size()) + " bytes (at most " + std::to_string(kMaxName) + ")");
  const fs::path path = (fs::path(file_).parent_path() / name).lexically_normal();
  if (path.native().size() > kMaxPath)
    u.fail("neither a data URI nor a usable file name: " + shown + " is " + std::to_string(name.size()) +
           " bytes long (a path has at most " + std::to_string(kMaxPath) + ")");
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::is_regular_file(st))
    u.fail("cannot open buffer file " + quoted_start(path.string()) +
           (ec ? ": " + ec.message() : fs::exists(st) ? ": not a regular file" : ": no such file"));
  if (!read_file_bytes(path.string(), out)) u.fail("cannot read buffer file " + quoted_start(path.string()));
}

const std::vector<std::uint8_t>& GltfReader::buffer(std::size_t i) {
  auto found = buffers_.find(i);
  if (found != buffers_.end()) return found->second;
  const JsonIn b = buffers_j_[i];
  const auto length = static_cast<std::size_t>(b.at("byteLength").integer(1, 1LL << 53));
  std::vector<std::uint8_t> data;
  if (auto u = b.find("uri")) {
    read_uri(*u, data);
  } else {
    if (!glb_) b.fail("buffer has no uri (only a .glb may leave it out, for its binary chunk)");
    if (i != 0) b.fail("buffer has no uri: only buffer 0 of a .glb refers to the binary chunk");
    if (!glb_has_bin_) b.fail("buffer refers to the binary chunk but the .glb has none");
    data = glb_bin_;
  }
  if (data.size() < length)
    b.at("byteLength").fail("byteLength is " + std::to_string(length) + " but the buffer holds " +
                            std::to_string(data.size()) + " bytes");
  data.resize(length);  // GLB padding beyond byteLength is not part of the buffer
  return buffers_.emplace(i, std::move(data)).first->second;
}

Accessor GltfReader::accessor(std::size_t i, const std::string& use) {
  const JsonIn a = accessors_j_[i];
  Accessor r;
  r.place = a.place();
  auto fail = [&](const std::string& why) { throw InputError(file_, r.place, why + " (" + use + ")"); };
  if (a.has("sparse")) fail("sparse accessors are not supported");
  r.component = a.at("componentType").integer(0, 1 << 20);
  if (component_size(r.component) == 0)
    a.at("componentType").fail("unknown componentType " + std::to_string(r.component));
  const std::string type = a.at("type").string();
  r.width = type_width(type);
  if (r.width == 0) a.at("type").fail("unknown accessor type \"" + type + "\"");
  r.count = a.at("count").integer(1, std::numeric_limits<std::uint32_t>::max());
  r.normalized = a.has("normalized") && a.at("normalized").boolean();
  const auto offset = static_cast<std::size_t>(a.integer_or("byteOffset", 0, 0, 1LL << 53));
  if (!a.has("bufferView")) fail("accessor has no bufferView (all zeros): not supported");
  const std::size_t vi = ref(a.at("bufferView"), views_j_, "bufferView");
  const JsonIn v = views_j_[vi];
  const std::size_t bi = ref(v.at("buffer"), buffers_j_, "buffer");
  const auto view_offset = static_cast<std::size_t>(v.integer_or("byteOffset", 0, 0, 1LL << 53));
  const auto view_length = static_cast<std::size_t>(v.at("byteLength").integer(1, 1LL << 53));
  const std::vector<std::uint8_t>& data = buffer(bi);
  if (view_offset > data.size() || view_length > data.size() - view_offset)
    v.fail("bufferView (offset " + std::to_string(view_offset) + ", length " + std::to_string(view_length) +
           ") runs past the end of buffer " + std::to_string(bi) + " (" + std::to_string(data.size()) + " bytes)");
  const std::size_t element = static_cast<std::size_t>(r.width) * component_size(r.component);
  r.stride = element;
  if (auto st = v.find("byteStride")) {
    r.stride = static_cast<std::size_t>(st->integer(4, 252));
    if (r.stride % 4) st->fail("byteStride must be a multiple of 4");
    if (r.stride < element)
      st->fail("byteStride " + std::to_string(r.stride) + " is smaller than an element of accessor " +
               std::to_string(i) + " (" + std::to_string(element) + " bytes)");
  }
  const std::size_t needed = offset + r.stride * static_cast<std::size_t>(r.count - 1) + element;
  if (needed > view_length)
    fail("accessor needs " + std::to_string(needed) + " bytes of bufferView " + std::to_string(vi) +
         " but it has " + std::to_string(view_length));
  r.data = data.data() + view_offset + offset;
  return r;
}

std::vector<double> GltfReader::read_floats(std::size_t i, int width, bool allow_normalized, const std::string& use) {
  const Accessor a = accessor(i, use);
  auto fail = [&](const std::string& why) { throw InputError(file_, a.place, why + " (" + use + ")"); };
  const char* want = width == 1 ? "SCALAR" : width == 3 ? "VEC3" : "VEC4";
  if (a.width != width) fail(std::string("expected type ") + want + ", found " + accessors_j_[i].at("type").string());
  const bool ok = a.component == kFloat ||
                  (allow_normalized && a.normalized && a.component != kUInt);
  if (!ok)
    fail(std::string("expected FLOAT components") + (allow_normalized ? " (or normalized integers)" : "") +
         ", found " + (a.normalized ? "normalized " : "") + component_name(a.component));
  std::vector<double> out(static_cast<std::size_t>(a.count) * width);
  const int cs = component_size(a.component);
  for (std::size_t e = 0; e < static_cast<std::size_t>(a.count); ++e) {
    const std::uint8_t* p = a.data + e * a.stride;
    for (int c = 0; c < width; ++c) {
      const double x = read_component(p + c * cs, a.component, a.normalized);
      if (!std::isfinite(x))
        fail("element " + std::to_string(e) + " has a " + (std::isnan(x) ? "NaN" : "infinite") + " component");
      out[e * width + c] = x;
    }
  }
  return out;
}

std::vector<std::uint32_t> GltfReader::read_indices(std::size_t i, const std::string& use) {
  const Accessor a = accessor(i, use);
  auto fail = [&](const std::string& why) { throw InputError(file_, a.place, why + " (" + use + ")"); };
  if (a.width != 1) fail("indices must be SCALAR, found " + accessors_j_[i].at("type").string());
  if (a.component != kUByte && a.component != kUShort && a.component != kUInt)
    fail(std::string("indices must be UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT, found ") + component_name(a.component));
  std::vector<std::uint32_t> out(static_cast<std::size_t>(a.count));
  for (std::size_t e = 0; e < out.size(); ++e)
    out[e] = static_cast<std::uint32_t>(read_component(a.data + e * a.stride, a.component, false));
  return out;
}

void GltfReader::refuse_deformation() {
  const std::string rigid = ": oprt models rigid objects";
  auto skins = list("skins");
  if (!skins.empty()) skins[0].fail("skins are not supported" + rigid);
  for (const JsonIn& n : nodes_j_)
    if (auto sk = n.find("skin")) sk->fail("skins are not supported" + rigid);
  for (const JsonIn& m : meshes_j_)
    for (const JsonIn& p : m.at("primitives").items())
      if (auto t = p.find("targets"))
        if (!t->items().empty()) t->fail("morph targets are not supported" + rigid);
}

void GltfReader::read_animations() {
  auto animations = list("animations");
  for (std::size_t a = 0; a < animations.size(); ++a) {
    const JsonIn anim = animations[a];
    const auto samplers = anim.at("samplers").items();
    const auto channels = anim.at("channels").items();
    for (const JsonIn& ch : channels) {
      const std::size_t si = ref(ch.at("sampler"), samplers, "sampler");
      const JsonIn target = ch.at("target");
      const JsonIn path_j = target.at("path");
      const std::string path = path_j.string();
      if (path == "weights") path_j.fail("morph target weights are not supported: oprt models rigid objects");
      if (path != "translation" && path != "rotation" && path != "scale")
        path_j.fail("unknown animation path \"" + path + "\" (expected translation, rotation or scale)");
      auto node_j = target.find("node");
      if (!node_j) {
        notes_.add("channel without node", "animation channel " + ch.place() + " has no target node: ignored");
        continue;
      }
      const std::size_t node = ref(*node_j, nodes_j_, "node");
      if (nodes_j_[node].has("matrix"))
        node_j->fail("node " + std::to_string(node) + " has a matrix; an animated node must use translation, rotation and scale");
      const auto key = std::make_pair(node, path);
      GltfSamplerPtr sampler = read_sampler(samplers[si], path, path_j);
      if (channels_.count(key)) {
        notes_.add("channel conflict", "animation channel " + ch.place() + " drives the " + path + " of node " +
                                           std::to_string(node) + " already driven by " + channel_place_[key] +
                                           ": ignored (the first one wins)");
        continue;
      }
      channels_[key] = sampler;
      channel_place_[key] = ch.place();
      if (sampler->last_time() > last_key_time_) {
        last_key_time_ = sampler->last_time();
        last_key_place_ = samplers[si].place() + "/input";
      }
    }
  }
}

GltfSamplerPtr GltfReader::read_sampler(const JsonIn& sj, const std::string& path, const JsonIn& channel_path) {
  auto s = std::make_shared<GltfSampler>();
  s->rotation = path == "rotation";
  s->width = s->rotation ? 4 : 3;
  const std::string interp = sj.string_or("interpolation", "LINEAR");
  if (interp == "LINEAR") s->interpolation = GltfSampler::Interpolation::linear;
  else if (interp == "STEP") s->interpolation = GltfSampler::Interpolation::step;
  else if (interp == "CUBICSPLINE") s->interpolation = GltfSampler::Interpolation::cubic_spline;
  else sj.at("interpolation").fail("unknown interpolation \"" + interp + "\" (expected LINEAR, STEP or CUBICSPLINE)");
  const JsonIn in_j = sj.at("input"), out_j = sj.at("output");
  const std::size_t in = ref(in_j, accessors_j_, "accessor");
  const std::size_t out = ref(out_j, accessors_j_, "accessor");
  s->times = read_floats(in, 1, false, "key times of " + sj.place());
  for (std::size_t k = 1; k < s->times.size(); ++k)
    if (!(s->times[k] > s->times[k - 1]))
      throw InputError(file_, accessors_j_[in].place(),
                       "key times must increase: element " + std::to_string(k) + " (" + number_text(s->times[k]) +
                           ") is not after " + number_text(s->times[k - 1]) + " (key times of " + sj.place() + ")");
  s->values = read_floats(out, s->width, s->rotation, path + " values of " + sj.place() + ", used by " + channel_path.place());
  const bool cubic = s->interpolation == GltfSampler::Interpolation::cubic_spline;
  const std::size_t keys = s->times.size(), values = s->values.size() / s->width;
  const std::size_t expected = cubic ? 3 * keys : keys;
  if (values != expected)
    out_j.fail("output has " + std::to_string(values) + " values for " + std::to_string(keys) + " key times (" +
               interp + " needs " + std::to_string(expected) + ")");
  // Keys that could never give an invertible transform (tangents may be anything).
  for (std::size_t k = 0; k < keys; ++k) {
    const double* v = s->values.data() + (cubic ? 3 * k + 1 : k) * s->width;
    if (s->rotation && v[0] == 0 && v[1] == 0 && v[2] == 0 && v[3] == 0)
      throw InputError(file_, accessors_j_[out].place(), "rotation key " + std::to_string(k) + " is a zero quaternion");
    if (path == "scale" && (v[0] == 0 || v[1] == 0 || v[2] == 0))
      throw InputError(file_, accessors_j_[out].place(),
                       "scale key " + std::to_string(k) + " has a zero component: the transform would be singular");
  }
  return s;
}

const GltfLocal& GltfReader::local(std::size_t i) {
  if (locals_[i]) return *locals_[i];
  const JsonIn n = nodes_j_[i];
  GltfLocal l;
  if (auto mj = n.find("matrix")) {
    if (n.has("translation") || n.has("rotation") || n.has("scale"))
      n.fail("node has both a matrix and translation/rotation/scale");
    const auto items = mj->items();
    if (items.size() != 16) mj->fail("expected 16 numbers (a column-major 4x4 matrix), found " + std::to_string(items.size()));
    double a[16];
    for (int k = 0; k < 16; ++k) a[k] = items[k].number();
    if (a[3] != 0 || a[7] != 0 || a[11] != 0 || a[15] != 1)
      mj->fail("not an affine matrix: the last row must be 0 0 0 1");
    Affine<double> m;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c) m.m[r][c] = a[4 * c + r];
    const std::string why = why_not_invertible(m);
    if (!why.empty()) mj->fail(why);
    l.matrix = m;
  } else {
    if (auto t = n.find("translation")) l.translation = vec3(*t);
    if (auto r = n.find("rotation")) {
      const auto q = r->items();
      if (q.size() != 4) r->fail("expected 4 numbers (a quaternion x, y, z, w), found " + std::to_string(q.size()));
      l.rotation.x = q[0].number();
      l.rotation.y = q[1].number();
      l.rotation.z = q[2].number();
      l.rotation.w = q[3].number();
      const double len2 = glm::dot(l.rotation, l.rotation);
      if (!(len2 > 0)) r->fail("rotation is a zero quaternion");
      l.rotation = glm::normalize(l.rotation);
    }
    if (auto s = n.find("scale")) {
      l.scale = vec3(*s);
      if (l.scale.x == 0 || l.scale.y == 0 || l.scale.z == 0)
        s->fail("scale has a zero component: the transform would be singular");
    }
    const std::string why = why_not_invertible(trs_affine(l.translation, l.rotation, l.scale));
    if (!why.empty()) n.fail(why);
    auto channel = [&](const char* path) {
      auto it = channels_.find({i, path});
      return it == channels_.end() ? nullptr : it->second;
    };
    l.translation_channel = channel("translation");
    l.rotation_channel = channel("rotation");
    l.scale_channel = channel("scale");
  }
  locals_[i] = l;
  return *locals_[i];
}

std::vector<std::size_t> GltfReader::scene_nodes() {
  parent_.assign(nodes_j_.size(), kNone);
  for (std::size_t i = 0; i < nodes_j_.size(); ++i) {
    auto ch = nodes_j_[i].find("children");
    if (!ch) continue;
    for (const JsonIn& cj : ch->items()) {
      const std::size_t c = ref(cj, nodes_j_, "node");
      if (c == i) cj.fail("node " + std::to_string(i) + " is its own child");
      if (parent_[c] != kNone)
        cj.fail("node " + std::to_string(c) + " is a child of both node " + std::to_string(parent_[c]) + " and node " +
                std::to_string(i) + " (the node hierarchy must be a tree)");
      parent_[c] = i;
    }
  }
  std::vector<std::size_t> roots;
  auto scenes = list("scenes");
  if (scenes.empty()) {
    for (std::size_t i = 0; i < nodes_j_.size(); ++i)
      if (parent_[i] == kNone) roots.push_back(i);
    if (!nodes_j_.empty()) notes_.add("no scenes", "the file has no scenes: every root node is shown");
  } else {
    const std::size_t si = root().has("scene") ? ref(root().at("scene"), scenes, "scene") : 0;
    if (auto nj = scenes[si].find("nodes")) {
      for (const JsonIn& rj : nj->items()) {
        const std::size_t r = ref(rj, nodes_j_, "node");
        if (parent_[r] != kNone)
          rj.fail("node " + std::to_string(r) + " is not a root node: it is a child of node " + std::to_string(parent_[r]));
        if (std::find(roots.begin(), roots.end(), r) != roots.end())
          rj.fail("node " + std::to_string(r) + " is listed twice");
        roots.push_back(r);
      }
    }
  }
  // Depth first, children in order, without recursion (hierarchies can be deep). Every node
  // has at most one parent and the roots have none, so no node is reached twice and a cycle
  // (which would have no root) is never entered.
  std::vector<std::size_t> order, stack(roots.rbegin(), roots.rend());
  while (!stack.empty()) {
    const std::size_t n = stack.back();
    stack.pop_back();
    order.push_back(n);
    if (auto ch = nodes_j_[n].find("children")) {
      const auto items = ch->items();
      for (auto it = items.rbegin(); it != items.rend(); ++it) stack.push_back(static_cast<std::size_t>(it->integer(0, nodes_j_.size())));
    }
  }
  return order;
}

std::vector<GltfLocal> GltfReader::chain(std::size_t node) {
  std::vector<std::size_t> path;
  for (std::size_t n = node; n != kNone; n = parent_[n]) path.push_back(n);
  std::vector<GltfLocal> c;
  for (auto it = path.rbegin(); it != path.rend(); ++it) c.push_back(local(*it));
  return c;
}

void GltfReader::read_materials() {
  // Every material is read (and checked) whether used or not; Object::material indexes them.
  bool textures = false, ignored_extensions = false;
  for (std::size_t i = 0; i < materials_j_.size(); ++i) {
    const JsonIn m = materials_j_[i];
    Vec3d base(1);
    double metallic = 1, roughness = 1;  // the glTF defaults
    if (auto pbr = m.find("pbrMetallicRoughness")) {
      if (auto f = pbr->find("baseColorFactor")) {
        const auto c = f->items();
        if (c.size() != 4) f->fail("expected 4 numbers (r, g, b, a), found " + std::to_string(c.size()));
        base = Vec3d(c[0].number(0, 1), c[1].number(0, 1), c[2].number(0, 1));
        c[3].number(0, 1);
      }
      metallic = pbr->number_or("metallicFactor", 1, 0, 1);
      roughness = pbr->number_or("roughnessFactor", 1, 0, 1);
      textures = textures || pbr->has("baseColorTexture") || pbr->has("metallicRoughnessTexture");
    }
    textures = textures || m.has("normalTexture") || m.has("occlusionTexture") || m.has("emissiveTexture");
    Material mat = pbr_to_phong(m.string_or("name", "material" + std::to_string(i)), base, metallic, roughness);
    // A perfect metal mirrors its base colour; rougher or partly metallic surfaces reflect
    // diffusely and get no mirror weight.
    if (metallic == 1 && roughness == 0) mat.reflect = base;
    std::optional<double> ior;
    if (auto ext = m.find("extensions")) {
      for (const auto& [name, e] : ext->members()) {
        if (name == "KHR_materials_transmission") {
          e.only_keys({"transmissionFactor", "transmissionTexture", "extensions", "extras"});
          mat.transmit = Vec3d(e.number_or("transmissionFactor", 0, 0, 1));
          textures = textures || e.has("transmissionTexture");
        } else if (name == "KHR_materials_ior") {
          e.only_keys({"ior", "extensions", "extras"});
          ior = e.number_or("ior", 1.5, 1, 10);
        } else {
          ignored_extensions = true;
        }
      }
    }
    // glTF's dielectrics have an index of 1.5 unless KHR_materials_ior says otherwise; the index
    // matters only to a material that transmits.
    mat.ior = ior ? *ior : (mat.transmits() ? 1.5 : 1.0);
    materials_.push_back(mat);
  }
  if (textures) notes_.add("textures", "textures are ignored: materials use their colour factors only");
  if (ignored_extensions)
    notes_.add("material extensions", "material extensions other than KHR_materials_transmission and "
                                      "KHR_materials_ior are ignored");
}

const std::vector<GltfReader::Group>& GltfReader::mesh_groups(std::size_t mi) {
  auto cached = mesh_groups_.find(mi);
  if (cached != mesh_groups_.end()) return cached->second;
  const JsonIn mesh = meshes_j_[mi];
  std::vector<Group> groups;
  const auto primitives = mesh.at("primitives").items();
  if (primitives.empty()) mesh.at("primitives").fail("a mesh needs at least one primitive");
  for (const JsonIn& p : primitives) {
    const long long mode = p.integer_or("mode", 4, 0, 6);
    if (mode < 4) {
      static const char* names[] = {"POINTS", "LINES", "LINE_LOOP", "LINE_STRIP"};
      notes_.add("non-triangle primitive", std::string(names[mode]) + " primitive " + p.place() +
                                               " skipped: only triangles are ray traced");
      continue;
    }
    const JsonIn attributes = p.at("attributes");
    const std::size_t pa = ref(attributes.at("POSITION"), accessors_j_, "accessor");
    const std::vector<double> pos = read_floats(pa, 3, false, "POSITION of " + p.place());
    const std::size_t nverts = pos.size() / 3;
    // NORMAL: one per vertex (float, or normalized integers under KHR_mesh_quantization).
    std::size_t na = kNone;
    std::vector<double> nrm;
    if (auto nj = attributes.find("NORMAL")) {
      na = ref(*nj, accessors_j_, "accessor");
      nrm = read_floats(na, 3, true, "NORMAL of " + p.place());
      if (nrm.size() != pos.size())
        nj->fail("NORMAL has " + std::to_string(nrm.size() / 3) + " elements, POSITION " + std::to_string(nverts) +
                 ": a normal per vertex is required");
    }
    std::vector<std::uint32_t> idx;
    std::string idx_place = attributes.at("POSITION").place();
    if (auto ij = p.find("indices")) {
      const std::size_t ia = ref(*ij, accessors_j_, "accessor");
      idx = read_indices(ia, "indices of " + p.place());
      idx_place = ij->place();
      for (std::size_t e = 0; e < idx.size(); ++e)
        if (idx[e] >= nverts)
          ij->fail("index " + std::to_string(idx[e]) + " (element " + std::to_string(e) + " of accessor " +
                   std::to_string(ia) + ") is out of range: POSITION has " + std::to_string(nverts) + " vertices");
    } else {
      idx.resize(nverts);
      for (std::size_t v = 0; v < nverts; ++v) idx[v] = static_cast<std::uint32_t>(v);
    }
    std::vector<Tri> tris;
    if (mode == 4) {
      if (idx.size() % 3)
        throw InputError(file_, idx_place, "a triangle list needs a multiple of 3 vertices, found " + std::to_string(idx.size()));
      for (std::size_t k = 0; k + 2 < idx.size(); k += 3) tris.push_back({idx[k], idx[k + 1], idx[k + 2]});
    } else {
      // Strips alternate winding to keep it consistent; strips and fans join pieces with
      // degenerate triangles, which are dropped.
      for (std::size_t k = 0; k + 2 < idx.size(); ++k) {
        Tri t = mode == 5 ? (k % 2 ? Tri{idx[k + 1], idx[k], idx[k + 2]} : Tri{idx[k], idx[k + 1], idx[k + 2]})
                          : Tri{idx[0], idx[k + 1], idx[k + 2]};
        if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) tris.push_back(t);
      }
    }
    std::uint32_t material;
    if (auto mj = p.find("material")) {
      material = static_cast<std::uint32_t>(ref(*mj, materials_j_, "material"));
    } else {
      if (default_material_ == kNone) {
        default_material_ = static_cast<std::uint32_t>(materials_.size());
        materials_.push_back(Material{"default", Vec3d(0.7), Vec3d(0.2), 32});
      }
      material = default_material_;
    }
    auto g = std::find_if(groups.begin(), groups.end(), [&](const Group& x) { return x.material == material; });
    if (g == groups.end()) g = groups.insert(groups.end(), Group{material, {}, {}, {}});
    // Only the vertices the triangles use join the object (they decide its bounding sphere);
    // primitives sharing a POSITION accessor share their vertices.
    std::vector<std::uint32_t>& remap = g->remap[pa];
    remap.resize(nverts, kNone);
    // Normals are indexed per corner (scene.h), so primitives sharing POSITION but not NORMAL
    // keep their vertices shared as before.
    Mesh& gm = g->mesh;
    if (na != kNone) gm.normal_index.resize(gm.triangles.size(), Tri{kNoNormal, kNoNormal, kNoNormal});
    std::vector<std::uint32_t>* nremap = na != kNone ? &g->nremap[na] : nullptr;
    if (nremap) nremap->resize(nverts, kNone);
    for (const Tri& t : tris) {
      Tri out;
      for (int k = 0; k < 3; ++k) {
        std::uint32_t& r = remap[t[k]];
        if (r == kNone) {
          r = static_cast<std::uint32_t>(gm.vertices.size());
          gm.vertices.push_back({pos[3 * t[k]], pos[3 * t[k] + 1], pos[3 * t[k] + 2]});
        }
        out[k] = r;
      }
      gm.triangles.push_back(out);
      if (!nremap) continue;
      Tri nout;
      bool ok = true;
      for (int k = 0; k < 3; ++k) {
        std::uint32_t& r = (*nremap)[t[k]];
        if (r == kNone) {
          r = static_cast<std::uint32_t>(gm.normals.size());
          gm.normals.push_back(unit_or_zero({nrm[3 * t[k]], nrm[3 * t[k] + 1], nrm[3 * t[k] + 2]}));
        }
        nout[k] = r;
        ok = ok && gm.normals[r] != Vec3d(0);
      }
      if (!ok) notes_.add("zero normal", "a triangle with a zero NORMAL (" + p.place() + ") is shaded flat");
      gm.normal_index.push_back(ok ? nout : Tri{kNoNormal, kNoNormal, kNoNormal});
    }
  }
  for (Group& g : groups) {
    // Primitives without NORMAL after one with: their triangles carry none.
    if (!g.mesh.normal_index.empty()) g.mesh.normal_index.resize(g.mesh.triangles.size(), Tri{kNoNormal, kNoNormal, kNoNormal});
    normals_read_ = normals_read_ || !g.mesh.normal_index.empty();
  }
  return mesh_groups_.emplace(mi, std::move(groups)).first->second;
}

void GltfReader::add_mesh_objects(std::size_t node, Scene& s) {
  const JsonIn nj = nodes_j_[node];
  const std::size_t mi = ref(nj.at("mesh"), meshes_j_, "mesh");
  const JsonIn mesh = meshes_j_[mi];
  const std::vector<Group>& groups = mesh_groups(mi);
  const std::string name = nj.string_or("name", mesh.string_or("name", "node" + std::to_string(node)));
  const MotionPtr motion = make_chain_motion(chain(node));
  for (const Group& g : groups) {
    if (g.mesh.triangles.empty()) continue;
    Object o;
    o.name = groups.size() > 1 ? name + "/" + materials_[g.material].name : name;
    o.material = g.material;
    o.mesh = g.mesh;
    o.motion = motion;
    s.objects.push_back(std::move(o));
  }
}

void GltfReader::add_camera(std::size_t node, Scene& s) {
  const std::size_t ci = ref(nodes_j_[node].at("camera"), cameras_j_, "camera");
  const JsonIn c = cameras_j_[ci];
  const std::string type = c.at("type").string();
  if (type == "orthographic") {
    notes_.add("orthographic camera", "orthographic camera " + c.place() + " ignored: oprt cameras are pinholes");
    return;
  }
  if (type != "perspective") c.at("type").fail("unknown camera type \"" + type + "\"");
  const JsonIn p = c.at("perspective");
  const double yfov = p.at("yfov").number();
  const double deg = glm::degrees(yfov);
  if (!(deg >= 1e-3 && deg <= 179))
    p.at("yfov").fail("vertical field of view " + number_text(yfov) + " rad is out of range (1e-3 to 179 degrees)");
  s.width = s.height = kImageRows;
  if (auto ar = p.find("aspectRatio")) {
    const double aspect = ar->number();
    const double w = std::round(kImageRows * aspect);
    if (!(w >= 1 && w <= 16384)) ar->fail("aspect ratio " + number_text(aspect) + " gives an image width out of range (1 to 16384 pixels)");
    s.width = static_cast<int>(w);
  }
  s.camera = std::make_shared<GltfCameraPath>(make_chain_motion(chain(node)), deg);
  camera_found_ = true;
}

void GltfReader::add_light(std::size_t node) {
  const JsonIn lj = nodes_j_[node].at("extensions").at("KHR_lights_punctual").at("light");
  const std::size_t li = ref(lj, lights_j_, "light");
  const JsonIn l = lights_j_[li];
  LightSource src;
  src.type = l.at("type").string();
  if (src.type != "point" && src.type != "spot" && src.type != "directional")
    l.at("type").fail("unknown light type \"" + src.type + "\" (expected point, spot or directional)");
  if (auto c = l.find("color")) {
    src.color = vec3(*c);
    if (src.color.x < 0 || src.color.y < 0 || src.color.z < 0) c->fail("light colour must not be negative");
  }
  src.intensity = l.number_or("intensity", 1, 0, 1e300);
  const MotionPtr m = make_chain_motion(chain(node));
  const Affine<double> at0 = m->at(0);
  src.position = at0.translation();
  src.direction = glm::normalize(at0.vector({0, 0, -1}));
  if (m->animated()) src.node = m;
  if (src.type == "spot")
    notes_.add("spot light", "spot light " + l.place() + " treated as a point light (its cone is ignored)");
  if (src.type == "directional")
    notes_.add("directional light", "directional light " + l.place() +
                                        " approximated by a point light 1000 scene radii away against its direction");
  lights_.push_back(src);
}

// The bounds of the scene over the whole animation: every object at every frame (a moving
// object's local box, its 8 corners carried by its motion), so that a default camera keeps
// in view what moves (Khronos' BoxAnimated lifts its inner box out of the frame-0 bounds).
// Objects sharing a motion (one node's primitives) are carried together. Past kMaxBoundsWork
// node transforms evaluated (frames x the links of every moving chain), the frames are
// sampled evenly, the last included: a deep hierarchy over a million frames stays quick.
void scene_bounds(const Scene& s, Vec3d& lo, Vec3d& hi) {
  constexpr long long kMaxBoundsWork = 1 << 22;
  lo = Vec3d(kInf<double>);
  hi = Vec3d(-kInf<double>);
  std::map<const Motion*, std::pair<Vec3d, Vec3d>> moving;  // local box per animated motion
  for (const Object& o : s.objects) {
    if (!o.motion->animated()) {
      const Affine<double> m = o.motion->at(0);
      for (const Vec3d& v : o.mesh.vertices) {
        lo = glm::min(lo, m.point(v));
        hi = glm::max(hi, m.point(v));
      }
      continue;
    }
    const auto it = moving.try_emplace(o.motion.get(), Vec3d(kInf<double>), Vec3d(-kInf<double>)).first;
    for (const Vec3d& v : o.mesh.vertices) {
      it->second.first = glm::min(it->second.first, v);
      it->second.second = glm::max(it->second.second, v);
    }
  }
  if (moving.empty()) return;
  long long links = 0;  // per frame
  for (const auto& [motion, box] : moving) {
    const auto* chain = dynamic_cast<const GltfChainMotion*>(motion);
    links += chain ? static_cast<long long>(chain->links()) : 1;
  }
  const long long frames = s.frame_count;
  const long long stride = std::max(1LL, (frames * links + kMaxBoundsWork - 1) / kMaxBoundsWork);
  std::vector<long long> sampled;
  for (long long f = 0; f < frames; f += stride) sampled.push_back(f);
  if (sampled.back() != frames - 1) sampled.push_back(frames - 1);
  for (long long f : sampled)
    for (const auto& [motion, box] : moving) {
      const Affine<double> m = motion->at(static_cast<double>(f));
      for (int c = 0; c < 8; ++c) {
        const Vec3d p = m.point({c & 1 ? box.second.x : box.first.x, c & 2 ? box.second.y : box.first.y,
                                 c & 4 ? box.second.z : box.first.z});
        lo = glm::min(lo, p);
        hi = glm::max(hi, p);
      }
    }
}

void GltfReader::finish_lights_and_camera(Scene& s) {
  // Bounds of the whole animation, for the default camera and the far "directional" lights.
  Vec3d lo, hi;
  scene_bounds(s, lo, hi);
  const Vec3d centre = (lo + hi) * 0.5;
  double radius = 0.5 * std::sqrt(dot3(hi - lo, hi - lo));
  if (!(radius > 0)) radius = 1;
  if (!camera_found_) {
    Camera c;
    c.fov_y_deg = 45;
    c.target = centre;
    c.eye = centre + Vec3d(0, 0, radius / std::sin(glm::radians(c.fov_y_deg / 2)));
    c.up = Vec3d(0, 1, 0);
    s.camera = std::make_shared<FixedCamera>(c);
    notes_.add("default camera", "no perspective camera: a default one (45 degrees) looks down -Z at the bounds of "
                                 "the whole animation");
  }
  double brightest = 0;
  for (const LightSource& l : lights_) brightest = std::max(brightest, l.intensity);
  for (const LightSource& l : lights_) {
    PointLight p;
    const double far = 1000 * radius;
    p.position = l.type == "directional" ? centre - l.direction * far : l.position;
    p.color = brightest > 0 ? l.color * (l.intensity / brightest) : Vec3d(0);
    if (l.node) {  // it follows its node, frame by frame
      const MotionPtr node = l.node;
      std::function<Vec3d(double)> where = [node](double f) { return node->at(f).translation(); };
      if (l.type == "directional")
        where = [node, centre, far](double f) { return centre - glm::normalize(node->at(f).vector({0, 0, -1})) * far; };
      p.motion = std::make_shared<GltfLightPath>(where, p.position);
    }
    s.lights.push_back(p);
  }
  if (!lights_.empty() && brightest != 1)
    notes_.add("light intensity", "light colours are colour x intensity / " + number_text(brightest) +
                                      " (the brightest light): oprt lights do not fall off with distance");
  if (lights_.empty()) {
    const Camera c = s.camera->at(0);
    const Vec3d forward = glm::normalize(c.target - c.eye);
    const Vec3d right = glm::normalize(cross3(forward, c.up));
    const Vec3d up = cross3(right, forward);
    const double d = std::max(std::sqrt(dot3(centre - c.eye, centre - c.eye)), radius);
    PointLight p;
    p.position = c.eye + (up + right) * (0.5 * d);
    s.lights.push_back(p);
    notes_.add("default light", "no lights: one white light above and to the right of the camera");
  }
}

Scene GltfReader::read() {
  parse_container();
  const JsonIn r = root();
  {
    const JsonIn v = r.at("asset").at("version");
    const std::string version = v.string();
    if (version.rfind("2.", 0) != 0) v.fail("glTF version \"" + version + "\" is not supported (expected 2.x)");
  }
  for (const JsonIn& e : list("extensionsRequired")) {
    const std::string name = e.string();
    const bool ok = name == "KHR_lights_punctual" || name.rfind("KHR_materials_", 0) == 0 || name.rfind("KHR_texture_", 0) == 0;
    if (!ok) e.fail("required extension \"" + name + "\" is not supported");
  }
  buffers_j_ = list("buffers");
  views_j_ = list("bufferViews");
  accessors_j_ = list("accessors");
  meshes_j_ = list("meshes");
  nodes_j_ = list("nodes");
  materials_j_ = list("materials");
  cameras_j_ = list("cameras");
  if (auto ext = r.find("extensions"))
    if (auto lp = ext->find("KHR_lights_punctual")) lights_j_ = lp->at("lights").items();
  locals_.assign(nodes_j_.size(), std::nullopt);

  refuse_deformation();
  read_materials();
  read_animations();

  Scene s;
  s.source = file_;
  s.materials = materials_;
  for (std::size_t n : scene_nodes()) {
    const JsonIn nj = nodes_j_[n];
    local(n);  // every node on the way is checked, even one without content
    if (nj.has("mesh")) add_mesh_objects(n, s);
    if (nj.has("camera") && !camera_found_) add_camera(n, s);
    if (auto ext = nj.find("extensions"))
      if (ext->has("KHR_lights_punctual")) add_light(n);
  }
  s.materials = materials_;  // with the default material if a primitive needed it
  if (s.objects.empty()) throw InputError(file_, "/", "the scene has no triangle meshes to render");

  if (last_key_time_ > 0) {
    const double frames = std::ceil(last_key_time_ * kGltfFramesPerSecond - 1e-9) + 1;
    if (!(frames <= kMaxFrames))
      throw InputError(file_, last_key_place_, "the animation lasts " + number_text(last_key_time_) + " s: more than " +
                                                   std::to_string(kMaxFrames) + " frames at 30 frames per second");
    s.frame_count = static_cast<int>(frames);
  }
  finish_lights_and_camera(s);
  if (normals_read_)
    notes_.add("normals", "vertex normals (NORMAL) read (oprt info counts the triangles that carry them): "
                          "interpolated for the lights' terms and the reflected and refracted directions");
  s.notes = notes_.lines();
  validate_scene(s);
  return s;
}

}  // namespace

Scene load_gltf(const std::string& path) { return GltfReader(path).read(); }

}  // namespace oprt
