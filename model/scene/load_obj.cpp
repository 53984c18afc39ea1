#include "base/error.h"
#include "base/read_file.h"
#include "scene/load.h"

#include <charconv>
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
// tinyobjloader reads a coordinate it cannot parse ("nan", "inf", "1e999", "x") as 0 and an
// index beyond int's range as whatever it wraps to, and says nothing: a silently wrong mesh.
// Check every vertex and face line first, with its number.
void check_lines(const std::string& path, const std::string& text) {
  std::istringstream in(text);
  std::string line;
  long long vertices = 0;
  for (std::size_t n = 1; std::getline(in, line); ++n) {
    line = line.substr(0, line.find('#'));  // a comment; also drops the \r of a CRLF file
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (line.size() < 2 || (line[0] != 'v' && line[0] != 'f') || (line[1] != ' ' && line[1] != '\t')) continue;
    const std::string where = "line " + std::to_string(n);
    std::istringstream fields(line.substr(2));
    std::string tok;
    if (line[0] == 'v') {
      ++vertices;
      for (int k = 0; k < 3; ++k) {
        if (!(fields >> tok)) throw InputError(path, where, "vertex needs 3 coordinates");
        char* end = nullptr;
        const double x = std::strtod(tok.c_str(), &end);
        if (end == tok.c_str() || *end != '\0') throw InputError(path, where, "\"" + tok + "\" is not a number");
        if (!std::isfinite(x)) throw InputError(path, where, "coordinate " + tok + " is not finite");
      }
      continue;
    }
    while (fields >> tok) {  // "i", "i/t", "i//n", "i/t/n": i is 1-based, or negative from the end
      const std::string index = tok.substr(0, tok.find('/'));
      long long i = 0;
      const auto r = std::from_chars(index.data(), index.data() + index.size(), i);
      if (r.ec != std::errc() || r.ptr != index.data() + index.size())
        throw InputError(path, where, "face vertex \"" + tok + "\" is not an index");
      if (i == 0 || i > vertices || -i > vertices)
        throw InputError(path, where, "vertex index " + index + " out of range (" + std::to_string(vertices) +
                                          " vertices before this line)");
    }
  }
}
}  // namespace

Mesh load_obj(const std::string& path) {
  const std::string text = read_file_text(path);
  check_lines(path, text);
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.vertex_color = false;
  // Parsed from memory with no material text: materials are not used, and an `mtllib` line
  // must not make the reader open another file (one named /dev/zero would never end).
  tinyobj::ObjReader reader;
  if (!reader.ParseFromString(text, "", config)) {
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
