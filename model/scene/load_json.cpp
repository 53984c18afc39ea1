// The oprt-scene/1 format (../../docs/scene-format.md has the full reference).
#include "scene/generate.h"
#include "scene/json_vec.h"
#include "scene/load.h"

#include <filesystem>
#include <map>

namespace oprt {

namespace {

std::string relative_to(const std::string& scene_file, const std::string& path) {
  namespace fs = std::filesystem;
  const fs::path p(path);
  if (p.is_absolute()) return path;
  return (fs::path(scene_file).parent_path() / p).lexically_normal().string();
}

Affine<double> read_transform(const JsonIn& t) {
  if (t.has("matrix")) {
    t.only_keys({"matrix"});
    const JsonIn m = t.at("matrix");
    auto items = m.items();
    if (items.size() != 12) m.fail("expected 12 numbers (a row-major 3x4 matrix), found " + std::to_string(items.size()));
    std::array<double, 12> a;
    for (int i = 0; i < 12; ++i) a[i] = items[i].number();
    const auto r = Affine<double>::from_rows(a);
    const std::string why = why_not_invertible(r);
    if (!why.empty()) m.fail(why);
    return r;
  }
  t.only_keys({"translate", "rotate", "scale"});
  RigidKey k;
  k.translate = vec3_or(t, "translate", Vec3d(0));
  if (auto r = t.find("rotate")) {
    r->only_keys({"axis", "deg"});
    const Vec3d axis = vec3_or(*r, "axis", Vec3d(0, 1, 0));
    if (dot3(axis, axis) == 0) r->at("axis").fail("rotation axis must not be zero");
    k.rotate = axis_angle(axis, r->number_or("deg", 0));
  }
  k.scale = t.number_or("scale", 1, 1e-12, 1e12);
  return to_affine(k);
}

MotionPtr read_animation(const JsonIn& a) {
  a.only_keys({"keyframes"});
  std::vector<RigidKey> keys;
  for (const JsonIn& kj : a.at("keyframes").items()) {
    kj.only_keys({"frame", "translate", "rotate", "scale"});
    RigidKey k;
    k.frame = kj.at("frame").number(-1e9, 1e9);
    if (!keys.empty() && !(k.frame > keys.back().frame))
      kj.at("frame").fail("keyframes must be in increasing frame order");
    k.translate = vec3_or(kj, "translate", keys.empty() ? Vec3d(0) : keys.back().translate);
    if (auto r = kj.find("rotate")) {
      r->only_keys({"axis", "deg"});
      const Vec3d axis = vec3_or(*r, "axis", Vec3d(0, 1, 0));
      if (dot3(axis, axis) == 0) r->at("axis").fail("rotation axis must not be zero");
      k.rotate = axis_angle(axis, r->number_or("deg", 0));
    } else if (!keys.empty()) {
      k.rotate = keys.back().rotate;
    }
    k.scale = kj.number_or("scale", keys.empty() ? 1.0 : keys.back().scale, 1e-12, 1e12);
    keys.push_back(k);
  }
  if (keys.empty()) a.at("keyframes").fail("animation needs at least one keyframe");
  return std::make_shared<KeyframeMotion>(std::move(keys));
}

// `budget`: what the scene may still have (SceneLimits); `depth`: parts nesting.
Mesh read_mesh(const JsonIn& mj, const std::string& scene_file, MeshBudget& budget, int depth = 0) {
  if (mj.has("obj")) {
    mj.only_keys({"obj", "transform"});
    const JsonIn o = mj.at("obj");
    const std::string path = relative_to(scene_file, o.string());
    if (!std::filesystem::exists(path)) o.fail("cannot open OBJ file " + path);
    try {
      require_regular_file(path);
    } catch (const InputError& e) {
      o.fail("OBJ file " + path + " " + e.problem());
    }
    Mesh m = load_obj(path);
    budget.charge(o.file(), o.place(), "the OBJ file " + path, m.vertices.size(), m.triangles.size());
    return m;
  }
  if (mj.has("generate")) {
    mj.only_keys({"generate", "transform"});
    return generate_from_json(mj.at("generate"), budget);
  }
  if (mj.has("parts")) {
    mj.only_keys({"parts", "transform"});
    if (depth >= scene_limits.parts_nesting)
      mj.fail("parts nested more than " + std::to_string(scene_limits.parts_nesting) + " deep");
    Mesh m;
    for (const JsonIn& part : mj.at("parts").items()) {
      const Affine<double> place =
          part.has("transform") ? read_transform(part.at("transform")) : Affine<double>::identity();
      m.append(read_mesh(part, scene_file, budget, depth + 1), place);
    }
    return m;
  }
  if (mj.has("vertices") || mj.has("triangles")) {
    mj.only_keys({"vertices", "triangles", "transform"});
    Mesh m;
    for (const JsonIn& v : mj.at("vertices").items()) m.vertices.push_back(vec3(v));
    for (const JsonIn& t : mj.at("triangles").items()) {
      auto idx = t.items();
      if (idx.size() != 3) t.fail("a triangle is 3 vertex indices, found " + std::to_string(idx.size()));
      Tri tri;
      for (int k = 0; k < 3; ++k)
        tri[k] = static_cast<std::uint32_t>(idx[k].integer(0, static_cast<long long>(m.vertices.size()) - 1));
      m.triangles.push_back(tri);
    }
    budget.charge(mj.file(), mj.at("triangles").place(), "this mesh", m.vertices.size(), m.triangles.size());
    return m;
  }
  mj.fail("a mesh needs \"obj\", \"vertices\" and \"triangles\", \"generate\", or \"parts\"");
}

// A weight per channel in [0, 1]: one number for all three, or [r, g, b].
Vec3d read_weight(const JsonIn& w) {
  if (w.is_number()) return Vec3d(w.number(0, 1));
  if (!w.is_array()) w.fail("expected a number or 3 numbers [r, g, b]");
  const auto c = w.items();
  if (c.size() != 3) w.fail("expected a number or 3 numbers [r, g, b], found " + std::to_string(c.size()) + " numbers");
  return {c[0].number(0, 1), c[1].number(0, 1), c[2].number(0, 1)};
}

Camera read_camera_fields(const JsonIn& c, const Camera& base) {
  Camera cam = base;
  cam.eye = vec3_or(c, "eye", base.eye);
  cam.target = vec3_or(c, "target", base.target);
  cam.up = vec3_or(c, "up", base.up);
  cam.fov_y_deg = c.number_or("fov_y_deg", base.fov_y_deg, 1e-3, 179);
  const Vec3d view = cam.target - cam.eye;
  if (dot3(view, view) == 0) c.fail("camera eye and target coincide");
  if (dot3(cross3(view, cam.up), cross3(view, cam.up)) == 0) c.fail("camera up is parallel to the view direction");
  return cam;
}

}  // namespace

Scene load_oprt_json(const std::string& path) {
  const nlohmann::json doc = JsonIn::parse_file(path);
  const JsonIn root(doc, path);
  root.only_keys({"format", "camera", "image", "background", "ambient", "lights", "materials",
                  "objects", "frames", "depth", "comment"});
  const std::string format = root.at("format").string();
  if (format != "oprt-scene/1") root.at("format").fail("unsupported format \"" + format + "\" (expected oprt-scene/1)");

  Scene s;
  s.source = path;
  {
    const JsonIn c = root.at("camera");
    c.only_keys({"eye", "target", "up", "fov_y_deg", "keyframes"});
    const Camera base = read_camera_fields(c, Camera{});
    if (auto keys = c.find("keyframes")) {
      std::vector<CameraKey> ks;
      for (const JsonIn& kj : keys->items()) {
        kj.only_keys({"frame", "eye", "target", "up", "fov_y_deg"});
        CameraKey k;
        k.frame = kj.at("frame").number(-1e9, 1e9);
        if (!ks.empty() && !(k.frame > ks.back().frame)) kj.at("frame").fail("keyframes must be in increasing frame order");
        k.camera = read_camera_fields(kj, ks.empty() ? base : ks.back().camera);
        ks.push_back(k);
      }
      if (ks.empty()) keys->fail("camera keyframes must not be empty");
      s.camera = std::make_shared<KeyframeCamera>(std::move(ks));
    } else {
      s.camera = std::make_shared<FixedCamera>(base);
    }
  }
  if (auto im = root.find("image")) {
    im->only_keys({"width", "height"});
    s.width = static_cast<int>(im->at("width").integer(1, 16384));
    s.height = static_cast<int>(im->at("height").integer(1, 16384));
  }
  s.background = vec3_or(root, "background", Vec3d(0));
  s.ambient = vec3_or(root, "ambient", Vec3d(0.1));
  if (auto lights = root.find("lights")) {
    for (const JsonIn& lj : lights->items()) {
      lj.only_keys({"position", "color"});
      s.lights.push_back({vec3(lj.at("position")), vec3_or(lj, "color", Vec3d(1)), nullptr});
    }
  }
  std::map<std::string, std::uint32_t> material_index;
  if (auto mats = root.find("materials")) {
    for (const auto& [name, mj] : mats->members()) {
      mj.only_keys({"diffuse", "specular", "shininess", "reflect", "transmit", "ior"});
      Material m;
      m.name = name;
      m.diffuse = vec3_or(mj, "diffuse", m.diffuse);
      m.specular = vec3_or(mj, "specular", m.specular);
      m.shininess = mj.number_or("shininess", m.shininess, 0, 1e6);
      if (auto r = mj.find("reflect")) m.reflect = read_weight(*r);
      if (auto t = mj.find("transmit")) m.transmit = read_weight(*t);
      m.ior = mj.number_or("ior", m.ior, 1, 10);
      material_index[name] = static_cast<std::uint32_t>(s.materials.size());
      s.materials.push_back(m);
    }
  }
  const std::uint32_t default_material = static_cast<std::uint32_t>(s.materials.size());
  bool default_used = false;
  MeshBudget budget;

  for (const JsonIn& oj : root.at("objects").items()) {
    oj.only_keys({"name", "material", "mesh", "transform", "animation"});
    Object o;
    o.name = oj.string_or("name", "object" + std::to_string(s.objects.size()));
    if (auto mat = oj.find("material")) {
      auto it = material_index.find(mat->string());
      if (it == material_index.end()) mat->fail("unknown material \"" + mat->string() + "\"");
      o.material = it->second;
    } else {
      o.material = default_material;
      default_used = true;
    }
    const JsonIn mj = oj.at("mesh");
    o.mesh = read_mesh(mj, path, budget);
    if (auto t = mj.find("transform")) {  // placement of the mesh in its own local frame
      Mesh placed;
      placed.append(o.mesh, read_transform(*t));
      o.mesh = std::move(placed);
    }
    if (o.mesh.triangles.empty()) mj.fail("mesh has no triangles");
    MotionPtr placement = std::make_shared<StaticMotion>(
        oj.has("transform") ? read_transform(oj.at("transform")) : Affine<double>::identity());
    // The keyframed motion moves the placed object: world = animation(f) * transform.
    o.motion = oj.has("animation")
                   ? std::make_shared<ComposedMotion>(read_animation(oj.at("animation")), placement)
                   : placement;
    s.objects.push_back(std::move(o));
  }
  if (default_used) s.materials.push_back(Material{"default", Vec3d(0.7), Vec3d(0.2), 32});
  if (s.materials.empty()) s.materials.push_back(Material{"default", Vec3d(0.7), Vec3d(0.2), 32});
  s.frame_count = static_cast<int>(root.integer_or("frames", 1, 1, 1000000));
  s.depth = static_cast<int>(root.integer_or("depth", Scene::kDefaultDepth, 0, kMaxDepth));
  validate_scene(s);
  return s;
}

}  // namespace oprt
