#include "scene/error.h"
#include "scene/load.h"

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

#include <tiny_obj_loader.h>

namespace oprt {

// All shapes and groups of the file become one mesh: one OBJ file is one rigid object.
// Polygons are triangulated by tinyobjloader (fan); normals and texture coordinates are not
// used (shading uses the geometric normal).
namespace {
// tinyobjloader reads a coordinate it cannot parse ("nan", "inf", "1e999", "x") as 0 and
// says nothing: a silently wrong vertex. Check every vertex line first, with its number.
void check_vertex_lines(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError(path, "", "cannot open file");
  std::string line;
  for (std::size_t n = 1; std::getline(in, line); ++n) {
    if (line.size() < 2 || line[0] != 'v' || (line[1] != ' ' && line[1] != '\t')) continue;
    std::istringstream fields(line.substr(2));
    std::string tok;
    for (int k = 0; k < 3; ++k) {
      if (!(fields >> tok))
        throw InputError(path, "line " + std::to_string(n), "vertex needs 3 coordinates");
      char* end = nullptr;
      const double x = std::strtod(tok.c_str(), &end);
      if (end == tok.c_str() || *end != '\0')
        throw InputError(path, "line " + std::to_string(n), "\"" + tok + "\" is not a number");
      if (!std::isfinite(x))
        throw InputError(path, "line " + std::to_string(n), "coordinate " + tok + " is not finite");
    }
  }
}
}  // namespace

Mesh load_obj(const std::string& path) {
  check_vertex_lines(path);
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  config.mtl_search_path = "";
  tinyobj::ObjReader reader;
  if (!reader.ParseFromFile(path, config)) {
    std::string err = reader.Error();
    while (!err.empty() && (err.back() == '\n' || err.back() == '\r')) err.pop_back();
    throw InputError(path, "", "malformed OBJ: " + (err.empty() ? std::string("parse failed") : err));
  }
  const auto& attrib = reader.GetAttrib();
  Mesh m;
  const std::size_t nv = attrib.vertices.size() / 3;
  m.vertices.reserve(nv);
  for (std::size_t i = 0; i < nv; ++i) {
    const Vec3d v{attrib.vertices[3 * i], attrib.vertices[3 * i + 1], attrib.vertices[3 * i + 2]};
    if (!all_finite(v))
      throw InputError(path, "vertex " + std::to_string(i + 1), "coordinate is not a finite number");
    m.vertices.push_back(v);
  }
  for (const auto& shape : reader.GetShapes()) {
    std::size_t offset = 0;
    for (std::size_t f = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
      const unsigned fv = shape.mesh.num_face_vertices[f];
      if (fv != 3)
        throw InputError(path, "shape \"" + shape.name + "\" face " + std::to_string(f + 1),
                         "face has " + std::to_string(fv) + " vertices after triangulation");
      Tri t;
      for (unsigned k = 0; k < 3; ++k) {
        const int idx = shape.mesh.indices[offset + k].vertex_index;
        if (idx < 0 || static_cast<std::size_t>(idx) >= nv)
          throw InputError(path, "shape \"" + shape.name + "\" face " + std::to_string(f + 1),
                           "vertex index " + std::to_string(idx + 1) + " out of range (file has " +
                               std::to_string(nv) + " vertices)");
        t[k] = static_cast<std::uint32_t>(idx);
      }
      m.triangles.push_back(t);
      offset += fv;
    }
  }
  if (m.triangles.empty()) throw InputError(path, "", "OBJ file has no faces");
  return m;
}

}  // namespace oprt
