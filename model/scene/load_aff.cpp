// BART AFF loader. The format, as BART's reference parser (parse.c) reads it:
//
//   v  from X Y Z  at X Y Z  up X Y Z  angle DEG  hither H  resolution W H
//   b R G B                      background
//   am R G B                     global ambient light (BART's default 1 1 1)
//   l X Y Z [R G B]              point light;  la NAME X Y Z [R G B]: animated light
//   f R G B Kd Ks Shine T ior    material (NFF);  fm AR AG AB DR DG DB SR SG SB Shine T ior
//   p N  (X Y Z) * N             polygon;  pp N (X Y Z NX NY NZ) * N: with normals
//   tt TEX (X Y Z U V) * 3       textured triangle;  ttp TEX (X Y Z NX NY NZ U V) * 3
//   m vertices N ... [normals N ...] [texturecoords N TEX (U V)*N] triangles N
//       (V0 V1 V2 [N0 N1 N2] [T0 T1 T2]) * N      indexed mesh
//   tpa N (TIME (X Y Z NX NY NZ) * 3) * N         triangle with per-vertex keyframes
//   s X Y Z R                    sphere;  c BX BY BZ BR AX AY AZ AR: cone (no caps)
//   i LEVEL FILE                 include (relative to the including file);  d LEVEL: detail
//   xs SX SY SZ  RX RY RZ DEG  TX TY TZ { ... }    static transform, M = T R S
//   x NAME { ... }               animated transform, moved by the keyframes "k NAME"
//   k NAME { transl N (T X Y Z t c b)*N  rot N (T AX AY AZ DEG t c b)*N
//            scale N (T X Y Z t c b)*N  visibility N (T 0|1)*N }
//   a START END FRAMES           animation range
//   # or % to the end of the line: comment
//
// Key times may go backwards or repeat, as BART's reader allows: such a list is evaluated as
// BART's code evaluates it (kb_spline.h; Anim::visible; tpa_corners), with one warning.
//
// The reader is token based: a statement is its keyword followed by whitespace-separated
// values, wherever the line breaks fall. The current material is global state, as in
// BART: it survives the end of a { } block and carries into and out of included files.
// Lights and the view are not moved by enclosing transforms (BART does not move them).
#include "scene/aff.h"

#include "base/error.h"
#include "scene/generate.h"
#include "scene/kb_spline.h"
#include "scene/load.h"

#include <algorithm>
#include <charconv>
#include <climits>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string_view>

namespace oprt {

namespace {

constexpr double kPi = 3.14159265358979323846;
// Deeper { } nesting is refused: it bounds the work per frame of a motion (one matrix per
// enclosing animated transform) and keeps every recursion over the tree shallow.
constexpr std::size_t kMaxNesting = 1000;

// ---------------------------------------------------------------------------------------
// Files and tokens

struct Token {
  std::string_view text;
  int line;
};

struct SourceFile {
  std::string path;  // normalised; named in errors
  std::string text;
  std::vector<Token> tokens;
  int last_line = 1;  // of the last token
};

std::shared_ptr<const SourceFile> read_source(const std::string& path) {
  auto f = std::make_shared<SourceFile>();
  f->path = path;
  std::ifstream in(path, std::ios::binary);
  if (!in) return nullptr;
  std::ostringstream ss;
  ss << in.rdbuf();
  f->text = ss.str();
  const std::string& s = f->text;
  int line = 1;
  std::size_t i = 0;
  const auto space = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v' || c == '\n'; };
  while (i < s.size()) {
    const char c = s[i];
    if (c == '\n') {
      ++line;
      ++i;
    } else if (space(c)) {
      ++i;
    } else if (c == '#' || c == '%') {
      while (i < s.size() && s[i] != '\n') ++i;
    } else if (c == '{' || c == '}') {
      f->tokens.push_back({std::string_view(s).substr(i, 1), line});
      ++i;
    } else {
      const std::size_t b = i;
      while (i < s.size() && !space(s[i]) && s[i] != '{' && s[i] != '}') ++i;
      f->tokens.push_back({std::string_view(s).substr(b, i - b), line});
    }
  }
  f->last_line = f->tokens.empty() ? 1 : f->tokens.back().line;  // errors at the end point here
  return f;
}

enum class NumKind { ok, not_finite, not_number };

NumKind parse_double(std::string_view t, double& v) {
  if (t.size() > 1 && t[0] == '+' && t[1] != '-' && t[1] != '+') t.remove_prefix(1);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  if (r.ec == std::errc::result_out_of_range) return NumKind::not_finite;
  if (r.ec != std::errc() || r.ptr != t.data() + t.size()) return NumKind::not_number;
  return std::isfinite(v) ? NumKind::ok : NumKind::not_finite;
}

bool is_number(std::string_view t) {
  double v;
  return parse_double(t, v) != NumKind::not_number;
}

bool is_keyword(std::string_view t) {
  static const std::set<std::string_view> k = {
      "v", "from", "at", "up", "angle", "hither", "resolution", "b", "am", "l", "la", "f", "fm", "p", "pp",
      "tt", "ttp", "m", "vertices", "normals", "texturecoords", "triangles", "tpa", "s", "c", "i", "d", "xs",
      "x", "k", "transl", "rot", "scale", "visibility", "a", "{", "}"};
  return k.count(t) > 0;
}

std::string shown(std::string_view t) {
  std::string s(t.substr(0, 40));
  if (t.size() > 40) s += "...";
  return "'" + s + "'";
}

// The statement being read: named in "wrong number of values" messages.
struct Stmt {
  std::string kw;
  int line;
};

class Cursor {
 public:
  explicit Cursor(const SourceFile& f) : f_(f) {}
  bool done() const { return i_ >= f_.tokens.size(); }
  const Token& peek() const { return f_.tokens[i_]; }
  const Token* ahead(std::size_t k) const { return i_ + k < f_.tokens.size() ? &f_.tokens[i_ + k] : nullptr; }
  void skip() { ++i_; }
  std::size_t left() const { return f_.tokens.size() - i_; }
  int line() const { return done() ? f_.last_line : f_.tokens[i_].line; }
  const std::string& file() const { return f_.path; }

  [[noreturn]] void fail(int line, const std::string& problem) const {
    throw InputError(f_.path, "line " + std::to_string(line), problem);
  }

  // The next token, which must exist: its absence is a "wrong number of values".
  const Token& take(const Stmt& s, const std::string& what) {
    if (done())
      fail(line(), "wrong number of values for '" + s.kw + "' at line " + std::to_string(s.line) + ": expected " +
                       what + ", found the end of the file");
    return f_.tokens[i_++];
  }

  double number(const Stmt& s, const std::string& what) {
    const Token& t = take(s, what);
    double v;
    switch (parse_double(t.text, v)) {
      case NumKind::ok:
        return v;
      case NumKind::not_finite:
        fail(t.line, shown(t.text) + " is not a finite number (" + what + " of '" + s.kw + "')");
      case NumKind::not_number:
        break;
    }
    if (is_keyword(t.text))
      fail(t.line, "wrong number of values for '" + s.kw + "' at line " + std::to_string(s.line) + ": expected " +
                       what + ", found " + shown(t.text));
    fail(t.line, shown(t.text) + " is not a number (expected " + what + " of '" + s.kw + "')");
  }

  Vec3d vec3(const Stmt& s, const std::string& what) {
    const double x = number(s, what + " x");
    const double y = number(s, what + " y");
    return {x, y, number(s, what + " z")};
  }

  long long integer(const Stmt& s, const std::string& what, long long lo, long long hi) {
    const Token& t = take(s, what);
    std::string_view txt = t.text;
    if (txt.size() > 1 && txt[0] == '+') txt.remove_prefix(1);
    long long v = 0;
    const auto r = std::from_chars(txt.data(), txt.data() + txt.size(), v);
    if (r.ec != std::errc() || r.ptr != txt.data() + txt.size()) {
      if (r.ec == std::errc::result_out_of_range) fail(t.line, what + " " + shown(t.text) + " is out of range");
      if (is_number(t.text)) fail(t.line, shown(t.text) + " is not an integer (expected " + what + " of '" + s.kw + "')");
      if (is_keyword(t.text))
        fail(t.line, "wrong number of values for '" + s.kw + "' at line " + std::to_string(s.line) + ": expected " +
                         what + ", found " + shown(t.text));
      fail(t.line, shown(t.text) + " is not a number (expected " + what + " of '" + s.kw + "')");
    }
    if (v < lo || v > hi)
      fail(t.line, what + " " + std::to_string(v) + " is out of range [" + std::to_string(lo) + ", " +
                       std::to_string(hi) + "]");
    return v;
  }

  // A name or file name: any token but a brace.
  std::string word(const Stmt& s, const std::string& what) {
    const Token& t = take(s, what);
    if (t.text == "{" || t.text == "}") fail(t.line, "expected " + what + " after '" + s.kw + "', found " + shown(t.text));
    return std::string(t.text);
  }

  int open_brace(const Stmt& s) {
    const Token& t = take(s, "'{'");
    if (t.text != "{") fail(t.line, "expected '{' after '" + s.kw + "' at line " + std::to_string(s.line) + ", found " + shown(t.text));
    return t.line;
  }

  // A count that announces `per` values each: refuse counts the file cannot hold, before
  // anything is allocated for them.
  std::size_t count(const Stmt& s, const std::string& what, std::size_t per, long long lo = 0) {
    const int at = line();
    const long long n = integer(s, what, lo, 1LL << 31);
    if (static_cast<unsigned long long>(n) * per > left())
      fail(at, "wrong number of values for '" + s.kw + "' at line " + std::to_string(s.line) + ": " + what + " " +
                   std::to_string(n) + " needs " + std::to_string(n * per) + " values, the file has " +
                   std::to_string(left()) + " left");
    return static_cast<std::size_t>(n);
  }

 private:
  const SourceFile& f_;
  std::size_t i_ = 0;
};

// ---------------------------------------------------------------------------------------
// Animation

struct Clock {  // frame -> BART animation time
  double start = 0, step = 0;
  double time(double frame) const { return start + frame * step; }
};

struct Anim {
  std::string name, file;
  int line = 0;
  std::optional<KbVecSpline> transl, scale;
  std::optional<KbRotSpline> rot;
  std::vector<std::pair<double, bool>> visibility;  // in the order written
  bool moves() const { return transl || rot || scale; }
  // BART's _GetVisibility, whatever the order of the keys: visible until the first key;
  // from there on, the flag of the key the walk through the list stops at.
  bool visible(double t) const {
    bool v = true;
    double prev = -kInf<double>;
    for (std::size_t q = 0; q < visibility.size(); ++q) {
      const auto& [time, flag] = visibility[q];
      if (t >= prev && t < time) return v;
      if (t >= time && q + 1 == visibility.size()) return flag;
      v = flag;
      prev = time;
    }
    return true;
  }

  // BART's _GetMatrix: T R S.
  Affine<double> matrix(double t) const {
    Affine<double> m = rot ? rotation_matrix(rot->at(t)) : Affine<double>::identity();
    if (scale) {
      const Vec3d s = scale->at(t);
      for (int i = 0; i < 3; ++i)
        for (int j = 0; j < 3; ++j) m.m[i][j] *= s[j];
    }
    if (transl) {
      const Vec3d p = transl->at(t);
      for (int i = 0; i < 3; ++i) m.m[i][3] = p[i];
    }
    return m;
  }
};
using AnimPtr = std::shared_ptr<const Anim>;

// The motion of an animated group: the product, outermost first, of each enclosing
// animated transform's static placement in its parent group and its keyframed matrix.
struct Link {
  Affine<double> pre;
  AnimPtr anim;  // null: an `x` without keyframes (identity, as in BART)
};

class AffMotion final : public Motion {
 public:
  AffMotion(std::vector<Link> chain, Clock clock) : chain_(std::move(chain)), clock_(clock) {
    for (const Link& l : chain_) animated_ = animated_ || (l.anim && l.anim->moves());
  }
  bool visible(double frame) const override {
    const double t = clock_.time(frame);
    for (const Link& l : chain_)
      if (l.anim && !l.anim->visible(t)) return false;
    return true;
  }
  Affine<double> at(double frame) const override {
    const double t = clock_.time(frame);
    Affine<double> m = Affine<double>::identity();
    for (const Link& l : chain_) {
      m = m * l.pre;
      if (l.anim && l.anim->moves()) m = m * l.anim->matrix(t);
    }
    return m;
  }
  bool animated() const override { return animated_; }

 private:
  std::vector<Link> chain_;
  Clock clock_;
  bool animated_ = false;
};

// `k camera`: the translation is the eye; the rotation turns the camera, which looks down
// its -z axis with +y up (BART's GetCamera). A part without keys keeps the view's value:
// the eye stays at `from`, or the viewing direction and up stay those of the view.
class AffCamera final : public CameraPath {
 public:
  AffCamera(const Camera& view, AnimPtr anim, Clock clock) : view_(view), anim_(std::move(anim)), clock_(clock) {}
  Camera at(double frame) const override {
    Camera c = view_;
    if (!anim_) return c;
    const double t = clock_.time(frame);
    Vec3d dir = view_.target - view_.eye;
    if (anim_->transl) c.eye = anim_->transl->at(t);
    if (anim_->rot) {
      const Affine<double> r = rotation_matrix(anim_->rot->at(t));
      dir = {-r.m[0][2], -r.m[1][2], -r.m[2][2]};
      c.up = {r.m[0][1], r.m[1][1], r.m[2][1]};
    }
    c.target = c.eye + dir;
    return c;
  }

 private:
  Camera view_;
  AnimPtr anim_;
  Clock clock_;
};

// `tpa`: each triangle's three vertices are interpolated linearly between its keys and held
// at or before the first key and at or after the last (BART's viGetAnimatedTriangle). In
// between, BART interpolates from key b - 1 to key b, b the first key later than t, whatever
// the order of the keys: key b - 1 is at or before t, so keys at one time are stepped over
// (never divided by). Vertex 3k + j is corner j of triangle k.
struct TpaTrack {
  std::vector<double> times;       // per key
  std::vector<double> reach;       // per key: the latest time of its triangle's keys up to it
  std::vector<Vec3d> corners;      // 3 per key
  std::vector<std::uint32_t> first;  // per triangle: its first key; keys run to first[k + 1]
};

void tpa_corners(const TpaTrack& tr, double t, std::vector<Vec3d>& out) {
  const std::size_t n = tr.first.size() - 1;
  out.resize(3 * n);
  for (std::size_t k = 0; k < n; ++k) {
    const std::uint32_t lo = tr.first[k], hi = tr.first[k + 1] - 1;
    std::size_t a = lo, b = lo;
    double s = 0;
    if (!(t > tr.times[lo])) {
      a = b = lo;
    } else if (!(t < tr.times[hi])) {
      a = b = hi;
    } else {
      // The first key later than t is the first whose reach is (reach never decreases).
      b = std::upper_bound(tr.reach.begin() + lo, tr.reach.begin() + hi + 1, t) - tr.reach.begin();
      a = b - 1;
      s = (t - tr.times[a]) / (tr.times[b] - tr.times[a]);
    }
    for (int j = 0; j < 3; ++j) {
      const Vec3d& pa = tr.corners[3 * a + j];
      const Vec3d& pb = tr.corners[3 * b + j];
      out[3 * k + j] = a == b ? pa : pa + (pb - pa) * s;
    }
  }
}

class TpaMotion final : public VertexMotion {
 public:
  TpaMotion(TpaTrack track, Clock clock) : track_(std::move(track)), clock_(clock) {}
  void at(double frame, std::vector<Vec3d>& vertices) const override {
    tpa_corners(track_, clock_.time(frame), vertices);
  }

 private:
  TpaTrack track_;
  Clock clock_;
};

// ---------------------------------------------------------------------------------------
// Geometry helpers

// Median split on triangle centroids along the longest axis of their bounds, until no part
// has more than `max` triangles. Parts come out in tree order (neighbours in space are
// neighbours in the list); each part lists its triangles in their original order.
std::vector<std::vector<std::uint32_t>> split_spatially(const Mesh& m, std::size_t max) {
  const std::size_t n = m.triangles.size();
  std::vector<std::uint32_t> idx(n);
  for (std::size_t i = 0; i < n; ++i) idx[i] = static_cast<std::uint32_t>(i);
  std::vector<std::vector<std::uint32_t>> parts;
  if (max == 0 || n <= max) {
    parts.push_back(std::move(idx));
    return parts;
  }
  std::vector<Vec3d> c(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Tri& t = m.triangles[i];
    c[i] = (m.vertices[t[0]] + m.vertices[t[1]] + m.vertices[t[2]]) / 3.0;
  }
  std::vector<std::pair<std::size_t, std::size_t>> stack{{0, n}};
  while (!stack.empty()) {  // depth first, lower half first: tree order
    const auto [lo, hi] = stack.back();
    stack.pop_back();
    if (hi - lo <= max) {
      std::vector<std::uint32_t> part(idx.begin() + lo, idx.begin() + hi);
      std::sort(part.begin(), part.end());
      parts.push_back(std::move(part));
      continue;
    }
    Vec3d bmin(kInf<double>), bmax(-kInf<double>);
    for (std::size_t i = lo; i < hi; ++i) {
      bmin = glm::min(bmin, c[idx[i]]);
      bmax = glm::max(bmax, c[idx[i]]);
    }
    const Vec3d ext = bmax - bmin;
    const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
    const std::size_t mid = lo + (hi - lo) / 2;
    // Ties broken by index: the split does not depend on the library's nth_element.
    std::nth_element(idx.begin() + lo, idx.begin() + mid, idx.begin() + hi, [&](std::uint32_t a, std::uint32_t b) {
      return c[a][axis] < c[b][axis] || (c[a][axis] == c[b][axis] && a < b);
    });
    stack.push_back({mid, hi});
    stack.push_back({lo, mid});
  }
  return parts;
}

// The listed triangles with only the vertices (and vertex normals) they use, renumbered in
// order of first use.
Mesh submesh(const Mesh& m, const std::vector<std::uint32_t>& tris) {
  Mesh out;
  std::vector<std::uint32_t> remap(m.vertices.size(), UINT32_MAX);
  std::vector<std::uint32_t> nremap(m.normals.size(), UINT32_MAX);
  out.triangles.reserve(tris.size());
  for (std::uint32_t t : tris) {
    Tri nt;
    for (int k = 0; k < 3; ++k) {
      std::uint32_t& r = remap[m.triangles[t][k]];
      if (r == UINT32_MAX) {
        r = static_cast<std::uint32_t>(out.vertices.size());
        out.vertices.push_back(m.vertices[m.triangles[t][k]]);
      }
      nt[k] = r;
    }
    out.triangles.push_back(nt);
    if (m.normal_index.empty()) continue;
    Tri ni = m.normal_index[t];
    if (ni[0] != kNoNormal) {
      for (int k = 0; k < 3; ++k) {
        std::uint32_t& r = nremap[ni[k]];
        if (r == UINT32_MAX) {
          r = static_cast<std::uint32_t>(out.normals.size());
          out.normals.push_back(m.normals[ni[k]]);
        }
        ni[k] = r;
      }
    }
    out.normal_index.push_back(ni);
  }
  // A part whose triangles all lack normals carries none.
  if (out.normals.empty()) out.normal_index.clear();
  return out;
}

// Corner normals indexed like the triangles; a triangle with a zero normal at a corner gets
// none (kNoNormal) and counts in `flat`.
void set_normals(Mesh& m, std::vector<Vec3d> normals, const std::vector<Tri>& index, std::size_t& flat) {
  m.normals = std::move(normals);
  m.normal_index.clear();
  m.normal_index.reserve(index.size());
  for (const Tri& t : index) {
    bool ok = true;
    for (std::uint32_t k : t) ok = ok && m.normals[k] != Vec3d(0);
    if (!ok) ++flat;
    m.normal_index.push_back(ok ? t : Tri{kNoNormal, kNoNormal, kNoNormal});
  }
}

// Open side surface of a cone or cylinder from `base` (radius rb) to `apex` (radius ra).
Mesh cone_mesh(const Vec3d& base, double rb, const Vec3d& apex, double ra, unsigned segments) {
  const Vec3d axis = glm::normalize(apex - base);
  const Vec3d helper = std::fabs(axis.x) < 0.9 ? Vec3d(1, 0, 0) : Vec3d(0, 1, 0);
  const Vec3d u = glm::normalize(cross3(axis, helper));
  const Vec3d v = cross3(axis, u);
  Mesh m;
  auto ring = [&](const Vec3d& centre, double r) -> std::uint32_t {
    const auto first = static_cast<std::uint32_t>(m.vertices.size());
    if (r == 0) {
      m.vertices.push_back(centre);
      return first;
    }
    for (unsigned i = 0; i < segments; ++i) {
      const double a = 2 * kPi * i / segments;
      m.vertices.push_back(centre + (u * std::cos(a) + v * std::sin(a)) * r);
    }
    return first;
  };
  const std::uint32_t b = ring(base, rb), a = ring(apex, ra);
  for (unsigned i = 0; i < segments; ++i) {
    const unsigned j = (i + 1) % segments;
    if (rb == 0) {
      m.triangles.push_back({b, a + j, a + i});
    } else if (ra == 0) {
      m.triangles.push_back({b + i, b + j, a});
    } else {
      m.triangles.push_back({b + i, b + j, a + j});
      m.triangles.push_back({b + i, a + j, a + i});
    }
  }
  return m;
}

// ---------------------------------------------------------------------------------------
// The reader

struct Node {
  int parent = -1;
  bool animated = false;
  std::string name;                                      // animated: the keyframes' name
  Affine<double> to_context = Affine<double>::identity();  // node frame -> its group's frame
  int context = 0;                                       // nearest animated node (self), 0 = world
  Affine<double> pre = Affine<double>::identity();       // animated: placement in the parent group
  std::string file;
  int line = 0;
};

struct MaterialInfo {
  Material m;
  Vec3d ka{0};
  bool has_ka = false;  // from `fm` (f has no ambient colour)
};

struct LightDef {
  PointLight light;
  std::string anim;  // `la`: the animation's name
};

struct View {
  Camera camera;
  int width = 0, height = 0;
};

class AffReader {
 public:
  explicit AffReader(const AffOptions& o) : opt_(o) {
    Node root;
    root.name = "static";
    nodes_.push_back(root);
  }

  Scene read(const std::string& path);
  void read_camera(Scene& s, std::set<std::string>& used_anims);
  void read_lights(Scene& s, std::set<std::string>& used_anims);
  void set_ambient(Scene& s, const std::vector<int>& mat_remap);
  void warn_tpa_backwards();
  void note_unused(const std::set<std::string>& used_anims);

 private:
  void parse_file(const std::string& path);
  void statement(Cursor& c, const Token& t, std::vector<std::pair<int, int>>& open);

  void view(Cursor& c, const Stmt& s);
  void light(Cursor& c, const Stmt& s, bool animated);
  void fill(Cursor& c, const Stmt& s, bool extended);
  void polygon(Cursor& c, const Stmt& s, bool patch);
  void textured(Cursor& c, const Stmt& s, bool patch);
  void mesh(Cursor& c, const Stmt& s);
  void animated_triangle(Cursor& c, const Stmt& s);
  void sphere(Cursor& c, const Stmt& s);
  void cone(Cursor& c, const Stmt& s);
  void include(Cursor& c, const Stmt& s);
  void keyframes(Cursor& c, const Stmt& s);

  void note(const std::string& n) {
    if (note_set_.insert(n).second) notes_.push_back(n);
  }
  // What the file gets wrong that BART tolerates: said once (a file included twice says it
  // once), as "FILE: line N: what and how it is read".
  void warn(const std::string& file, int line, const std::string& text) {
    const std::string w = file + ": line " + std::to_string(line) + ": " + text;
    if (warning_set_.insert(w).second) warnings_.push_back(w);
  }
  void note_normals() {
    note("vertex normals read (oprt info counts the triangles that carry them): interpolated for the lights' "
         "terms and the reflected and refracted directions; the geometric normal decides which lights face a "
         "surface");
  }
  void time_quirks(const std::string& file, int line, const std::string& list, const std::vector<double>& times,
                   const std::vector<int>& lines, bool steps);
  std::uint32_t material() {
    if (current_material_ < 0) {
      note("geometry before any material ('f' / 'fm') uses a default grey");
      current_material_ = static_cast<int>(add_material({Material{"default", Vec3d(0.7), Vec3d(0.2), 32}, {}, false}));
    }
    return static_cast<std::uint32_t>(current_material_);
  }
  std::uint32_t add_material(const MaterialInfo& mi);
  // Rigid geometry in the current node's frame, counted against the scene's limits.
  void emit(const Cursor& c, const Stmt& s, const Mesh& m);
  MeshBudget budget_;

  const AffOptions& opt_;
  std::vector<Node> nodes_;
  std::vector<int> stack_{0};  // open transform nodes; the world at the bottom
  std::vector<MaterialInfo> materials_;
  std::map<std::array<double, 9>, std::uint32_t> material_index_;
  std::size_t flat_normal_triangles_ = 0;  // triangles with a zero vertex normal (flat)
  int current_material_ = -1;
  std::map<std::pair<int, std::uint32_t>, Mesh> rigid_;       // (group, material)
  std::map<std::pair<int, std::uint32_t>, TpaTrack> tpa_;     // (group, material)
  std::map<std::string, std::shared_ptr<Anim>> anims_;
  std::vector<LightDef> lights_;
  std::optional<View> view_;
  Vec3d background_{0};
  Vec3d ambient_{1};  // BART's default
  Clock clock_;
  int frames_ = 1;
  std::map<std::string, std::shared_ptr<const SourceFile>> cache_;
  std::vector<std::string> including_;  // the include chain, for cycle errors
  std::vector<std::string> notes_;
  std::set<std::string> note_set_;
  std::vector<std::string> warnings_;
  std::set<std::string> warning_set_;
  struct TpaBackwards {  // the first key that goes back in the first such 'tpa' of a file
    int line, key_line;
    std::size_t key, keys;
    double time, after;
    std::set<int> lists;  // lines of the file's 'tpa' statements whose times go backwards
  };
  std::map<std::string, TpaBackwards> tpa_backwards_;  // by file
};

std::string time_text(double t) {
  std::ostringstream s;
  s << t;
  return s.str();
}

// One warning per key list whose times go backwards or repeat inside the curve (see
// kb_time_quirks), naming the first key of each kind. `steps`: visibility keys, where a
// repeated time is harmless (the later key holds from then on) and only going back counts.
void AffReader::time_quirks(const std::string& file, int line, const std::string& list,
                            const std::vector<double>& times, const std::vector<int>& lines, bool steps) {
  KbTimeQuirks q = kb_time_quirks(times);
  if (steps) q.repeat = 0;
  if (!q.backwards && !q.repeat) return;
  auto key = [&](std::size_t i) {
    return "key " + std::to_string(i + 1) + " of " + std::to_string(times.size()) + " (line " +
           std::to_string(lines[i]) + ") at time " + time_text(times[i]);
  };
  auto more = [](std::size_t count) {
    return count > 1 ? " (and " + std::to_string(count - 1) + " more like it)" : std::string();
  };
  std::string what;
  if (q.backwards)
    what = "times go backwards: " + key(q.backwards) + " after " + time_text(times[q.backwards - 1]) +
           more(q.backwards_count);
  if (q.repeat) what += std::string(what.empty() ? "" : "; ") + "a time repeats: " + key(q.repeat) + more(q.repeat_count);
  const std::string how = steps ? "read as BART reads them (its _GetVisibility walk through the list as written)"
                                : "read as BART reads them (at time t, the first spline segment that ends after t; "
                                  "the curve jumps where a segment would run backwards or have no length)";
  warn(file, line, list + ": " + what + "; " + how);
}

std::uint32_t AffReader::add_material(const MaterialInfo& mi) {
  // reflect is the specular colour (fill()): the key holds it once.
  const std::array<double, 9> key{mi.m.diffuse.x,  mi.m.diffuse.y,  mi.m.diffuse.z,   mi.m.specular.x, mi.m.specular.y,
                                  mi.m.specular.z, mi.m.shininess, mi.m.transmit.x, mi.m.ior};
  const auto it = material_index_.find(key);
  if (it != material_index_.end()) return it->second;
  const auto i = static_cast<std::uint32_t>(materials_.size());
  materials_.push_back(mi);
  material_index_[key] = i;
  return i;
}

void AffReader::emit(const Cursor& c, const Stmt& s, const Mesh& m) {
  budget_.charge(c.file(), "line " + std::to_string(s.line), "this statement", m.vertices.size(), m.triangles.size());
  const Node& n = nodes_[stack_.back()];
  rigid_[{n.context, material()}].append(m, n.to_context);
}

void AffReader::parse_file(const std::string& path) {
  std::shared_ptr<const SourceFile>& src = cache_[path];
  if (!src) {
    src = read_source(path);
    if (!src) throw InputError(path, "", "cannot read the file");
  }
  including_.push_back(path);
  Cursor c(*src);
  std::vector<std::pair<int, int>> open;  // blocks opened in this file: (stack depth, line of '{')
  std::optional<Stmt> last;
  while (!c.done()) {
    const Token t = c.peek();
    c.skip();
    if (is_number(t.text)) {
      if (last)
        c.fail(t.line, "wrong number of values: unexpected number " + shown(t.text) + " after '" + last->kw +
                           "' at line " + std::to_string(last->line));
      c.fail(t.line, "unexpected number " + shown(t.text) + " where a keyword should be");
    }
    statement(c, t, open);
    last = Stmt{std::string(t.text), t.line};
  }
  if (!open.empty())
    c.fail(open.back().second, "unterminated '{': no matching '}' before the end of the file");
  including_.pop_back();
}

void AffReader::statement(Cursor& c, const Token& t, std::vector<std::pair<int, int>>& open) {
  const std::string_view kw = t.text;
  const Stmt s{std::string(kw), t.line};
  if (kw == "}") {
    if (open.empty()) c.fail(t.line, "'}' without a matching '{'");
    stack_.pop_back();
    open.pop_back();
  } else if (kw == "{") {
    c.fail(t.line, "unexpected '{' (a block opens only after 'xs ...' or 'x NAME')");
  } else if (kw == "v") {
    view(c, s);
  } else if (kw == "b") {
    background_ = c.vec3(s, "background colour");
  } else if (kw == "am") {
    ambient_ = c.vec3(s, "ambient colour");
  } else if (kw == "l" || kw == "la") {
    light(c, s, kw == "la");
  } else if (kw == "f" || kw == "fm") {
    fill(c, s, kw == "fm");
  } else if (kw == "p" || kw == "pp") {
    polygon(c, s, kw == "pp");
  } else if (kw == "tt" || kw == "ttp") {
    textured(c, s, kw == "ttp");
  } else if (kw == "m") {
    mesh(c, s);
  } else if (kw == "tpa") {
    animated_triangle(c, s);
  } else if (kw == "s") {
    sphere(c, s);
  } else if (kw == "c") {
    cone(c, s);
  } else if (kw == "i") {
    include(c, s);
  } else if (kw == "d") {
    c.integer(s, "detail level", -1000000, 1000000);
    note("detail level ('d') ignored: kept at BART's default 0");
  } else if (kw == "xs") {
    const Vec3d sc = c.vec3(s, "scale");
    const Vec3d axis = c.vec3(s, "rotation axis");
    const double deg = c.number(s, "rotation angle");
    const Vec3d tr = c.vec3(s, "translation");
    if (dot3(axis, axis) == 0 && deg != 0) c.fail(t.line, "static transform: rotation axis is zero");
    const Affine<double> m = translate(tr) *
                             (dot3(axis, axis) == 0 ? Affine<double>::identity() : rotate(axis, deg * kPi / 180)) *
                             scale(sc);
    const std::string why = why_not_invertible(m);
    if (!why.empty()) c.fail(t.line, "static transform: " + why);
    const int brace = c.open_brace(s);
    if (stack_.size() > kMaxNesting) c.fail(brace, "blocks nested more than " + std::to_string(kMaxNesting) + " deep");
    const Node& parent = nodes_[stack_.back()];
    Node n;
    n.parent = stack_.back();
    n.to_context = parent.to_context * m;
    n.context = parent.context;
    n.file = c.file();
    n.line = t.line;
    nodes_.push_back(n);
    stack_.push_back(static_cast<int>(nodes_.size() - 1));
    open.push_back({static_cast<int>(stack_.size()), brace});
  } else if (kw == "x") {
    const std::string name = c.word(s, "a transform name");
    const int brace = c.open_brace(s);
    if (stack_.size() > kMaxNesting) c.fail(brace, "blocks nested more than " + std::to_string(kMaxNesting) + " deep");
    const Node& parent = nodes_[stack_.back()];
    Node n;
    n.parent = stack_.back();
    n.animated = true;
    n.name = name;
    n.pre = parent.to_context;
    n.context = static_cast<int>(nodes_.size());
    n.file = c.file();
    n.line = t.line;
    nodes_.push_back(n);
    stack_.push_back(n.context);
    open.push_back({static_cast<int>(stack_.size()), brace});
  } else if (kw == "k") {
    keyframes(c, s);
  } else if (kw == "a") {
    const double start = c.number(s, "start time");
    const double end = c.number(s, "end time");
    frames_ = static_cast<int>(c.integer(s, "number of frames", 1, 10000000));
    clock_.start = start;
    clock_.step = frames_ > 1 ? (end - start) / (frames_ - 1) : 0.0;
  } else {
    c.fail(t.line, "unknown keyword " + shown(kw));
  }
}

void AffReader::view(Cursor& c, const Stmt& s) {
  static const char* const kParts[] = {"from", "at", "up", "angle", "hither", "resolution"};
  bool seen[6] = {};
  View v;
  Vec3d from(0), at(0), up(0);
  double angle = 0;
  for (int done = 0; done < 6; ++done) {
    if (c.done() || std::find_if(std::begin(kParts), std::end(kParts), [&](const char* p) {
                      return c.peek().text == p;
                    }) == std::end(kParts)) {
      std::string missing;
      for (int i = 0; i < 6; ++i)
        if (!seen[i]) missing += std::string(missing.empty() ? "" : ", ") + "'" + kParts[i] + "'";
      c.fail(c.line(), "view ('v') at line " + std::to_string(s.line) + " is missing " + missing);
    }
    const Token& part = c.peek();
    const int which = static_cast<int>(
        std::find_if(std::begin(kParts), std::end(kParts), [&](const char* p) { return part.text == p; }) -
        std::begin(kParts));
    if (seen[which]) c.fail(part.line, "view ('v') gives '" + std::string(part.text) + "' twice");
    seen[which] = true;
    c.skip();
    const Stmt sub{std::string(part.text), part.line};
    switch (which) {
      case 0: from = c.vec3(sub, "eye position"); break;
      case 1: at = c.vec3(sub, "look-at point"); break;
      case 2: up = c.vec3(sub, "up vector"); break;
      case 3:
        angle = c.number(sub, "field of view in degrees");
        if (!(angle > 0 && angle < 180)) c.fail(part.line, "view angle must be between 0 and 180 degrees");
        break;
      case 4:
        c.number(sub, "hither distance");
        break;
      case 5:
        v.width = static_cast<int>(c.integer(sub, "horizontal resolution", 1, 16384));
        v.height = static_cast<int>(c.integer(sub, "vertical resolution", 1, 16384));
        break;
    }
  }
  const Vec3d dir = at - from;
  if (dot3(dir, dir) == 0) c.fail(s.line, "view: 'from' and 'at' coincide");
  if (dot3(cross3(dir, up), cross3(dir, up)) == 0) c.fail(s.line, "view: 'up' is parallel to the viewing direction");
  // The AFF angle is the vertical field of view (BART: "if the width is different from the
  // height ... the FOV in the y-direction"); the near plane has no counterpart here.
  v.camera = Camera{from, at, up, angle};
  view_ = v;
  note("view 'hither' (near clipping distance) ignored");
}

void AffReader::light(Cursor& c, const Stmt& s, bool animated) {
  LightDef l;
  if (animated) l.anim = c.word(s, "a light name");
  l.light.position = c.vec3(s, "light position");
  // Optional colour: exactly three numbers or none.
  int numbers = 0;
  while (numbers < 3 && c.ahead(numbers) && is_number(c.ahead(numbers)->text)) ++numbers;
  if (numbers == 3) {
    l.light.color = c.vec3(s, "light colour");
  } else if (numbers != 0) {
    c.fail(c.line(), "wrong number of values for '" + s.kw + "' at line " + std::to_string(s.line) +
                         ": a light's colour is 3 numbers (or none), found " + std::to_string(numbers));
  }
  lights_.push_back(l);
}

// Materials, for Phong shading with one diffuse and one specular colour:
// - `fm` (BART's extension): diffuse = the diffuse colour, specular = the specular colour,
//   shininess = Shine. Its ambient colour ka has no slot in Material: the renderer's
//   ambient term is Scene::ambient x diffuse, so BART's am x ka is matched by setting
//   Scene::ambient = am x r, with r the median ka / kd of the scene's fm materials: exact
//   when every material has ka = r kd, as most of BART's do (ka = 0.2 kd); the others
//   (metals with kd = 0, for one) get an ambient term that is too dark or too bright.
// - `f` (NFF): diffuse = Kd x colour, specular = Ks x white (NFF highlights are white),
//   shininess = Shine.
// The Whitted terms, as NFF (whose `f` this is) means them: in Whitted's model (CACM 1980,
// I = Ia + kd sum(N.L) + ks S + kt T) the specular coefficient weights the reflected ray S and
// T the refracted one. So reflect = the specular colour (fm) or Ks x white (f), transmit =
// T x white, ior = the index of refraction (1 where T is 0: BART's files write 0 there, an
// index nothing uses). Whitted's recursion (ref/shading.h) traces a reflection ray where
// reflect is non-zero and a refraction ray where transmit is, to the depth bound (--depth,
// default 5); `oprt info` lists them (docs/aff.md, "Materials").
void AffReader::fill(Cursor& c, const Stmt& s, bool extended) {
  MaterialInfo mi;
  if (extended) {
    mi.ka = c.vec3(s, "ambient colour");
    mi.has_ka = true;
    mi.m.diffuse = c.vec3(s, "diffuse colour");
    mi.m.specular = c.vec3(s, "specular colour");
  } else {
    const Vec3d rgb = c.vec3(s, "colour");
    const double kd = c.number(s, "Kd");
    const double ks = c.number(s, "Ks");
    mi.m.diffuse = rgb * kd;
    mi.m.specular = Vec3d(ks);
  }
  const int shine_line = c.line();
  mi.m.shininess = c.number(s, "Phong exponent (Shine)");
  if (mi.m.shininess < 0 || mi.m.shininess > 1e6) c.fail(shine_line, "Phong exponent must be in [0, 1e6]");
  const double transmit = c.number(s, "transmittance T");
  const double ior = c.number(s, "index of refraction");
  mi.m.reflect = mi.m.specular;
  mi.m.transmit = Vec3d(transmit);
  mi.m.ior = transmit != 0 ? ior : 1.0;
  if (mi.m.reflects() || transmit != 0)
    note("materials' reflection (specular colour) and transmittance with index of refraction read: traced as "
         "reflection and refraction rays to --depth (default 5); nested transparent media are not tracked");
  mi.m.name = std::filesystem::path(c.file()).filename().string() + ":" + std::to_string(s.line);
  current_material_ = static_cast<int>(add_material(mi));
}

void AffReader::polygon(Cursor& c, const Stmt& s, bool patch) {
  const int at = c.line();
  const std::size_t n = c.count(s, "vertex count", patch ? 6 : 3);
  if (n < 3) c.fail(at, "a polygon needs at least 3 vertices, found " + std::to_string(n));
  Mesh m;
  std::vector<Vec3d> normals;
  for (std::size_t i = 0; i < n; ++i) {
    m.vertices.push_back(c.vec3(s, "vertex " + std::to_string(i)));
    if (patch) normals.push_back(unit_or_zero(c.vec3(s, "normal " + std::to_string(i))));
  }
  for (std::uint32_t i = 1; i + 1 < n; ++i) m.triangles.push_back({0, i, i + 1});  // fan
  if (patch) {
    set_normals(m, std::move(normals), m.triangles, flat_normal_triangles_);
    note_normals();
  }
  emit(c, s, m);
}

void AffReader::textured(Cursor& c, const Stmt& s, bool patch) {
  c.word(s, "a texture name");
  Mesh m;
  std::vector<Vec3d> normals;
  for (int i = 0; i < 3; ++i) {
    m.vertices.push_back(c.vec3(s, "vertex " + std::to_string(i)));
    if (patch) normals.push_back(unit_or_zero(c.vec3(s, "normal " + std::to_string(i))));
    c.number(s, "texture u");
    c.number(s, "texture v");
  }
  m.triangles.push_back({0, 1, 2});
  note("textures ignored: textured triangles and texture coordinates load as plain geometry");
  if (patch) {
    set_normals(m, std::move(normals), m.triangles, flat_normal_triangles_);
    note_normals();
  }
  emit(c, s, m);
}

void AffReader::mesh(Cursor& c, const Stmt& s) {
  auto expect = [&](const char* word) {
    const Token& t = c.take(s, std::string("'") + word + "'");
    if (t.text != word)
      c.fail(t.line, "mesh ('m') at line " + std::to_string(s.line) + ": expected '" + word + "', found " + shown(t.text));
  };
  expect("vertices");
  Mesh m;
  const std::size_t nv = c.count(s, "vertex count", 3);
  m.vertices.reserve(nv);
  for (std::size_t i = 0; i < nv; ++i) m.vertices.push_back(c.vec3(s, "vertex " + std::to_string(i)));
  std::size_t nn = 0, nt = 0;
  bool normals = false, texcoords = false;
  std::vector<Vec3d> normal_list;
  if (!c.done() && c.peek().text == "normals") {
    c.skip();
    normals = true;
    nn = c.count(s, "normal count", 3);
    normal_list.reserve(nn);
    for (std::size_t i = 0; i < nn; ++i) normal_list.push_back(unit_or_zero(c.vec3(s, "normal " + std::to_string(i))));
    note_normals();
  }
  if (!c.done() && c.peek().text == "texturecoords") {
    c.skip();
    texcoords = true;
    nt = c.count(s, "texture coordinate count", 2);
    c.word(s, "a texture name");
    for (std::size_t i = 0; i < nt; ++i) {
      c.number(s, "texture u " + std::to_string(i));
      c.number(s, "texture v " + std::to_string(i));
    }
    note("textures ignored: textured triangles and texture coordinates load as plain geometry");
  }
  expect("triangles");
  const std::size_t per = 3 + (normals ? 3 : 0) + (texcoords ? 3 : 0);
  const std::size_t ntri = c.count(s, "triangle count", per);
  m.triangles.reserve(ntri);
  std::vector<Tri> normal_index;
  auto index = [&](const char* what, const char* plural, std::size_t limit, std::size_t tri) {
    const int at = c.line();
    const long long v = c.integer(s, std::string(what) + " index", LLONG_MIN, LLONG_MAX);
    if (v < 0 || static_cast<unsigned long long>(v) >= limit)
      c.fail(at, std::string(what) + " index " + std::to_string(v) + " of triangle " + std::to_string(tri) +
                     " out of range: the mesh has " + std::to_string(limit) + " " + (limit == 1 ? what : plural));
    return static_cast<std::uint32_t>(v);
  };
  for (std::size_t i = 0; i < ntri; ++i) {
    Tri t;
    for (int k = 0; k < 3; ++k) t[k] = index("vertex", "vertices", nv, i);
    if (normals) {  // BART's order: the three vertex indices, then the three normal indices
      Tri n;
      for (int k = 0; k < 3; ++k) n[k] = index("normal", "normals", nn, i);
      normal_index.push_back(n);
    }
    if (texcoords)
      for (int k = 0; k < 3; ++k) index("texture coordinate", "texture coordinates", nt, i);
    m.triangles.push_back(t);
  }
  if (normals) set_normals(m, std::move(normal_list), normal_index, flat_normal_triangles_);
  emit(c, s, m);
}

void AffReader::animated_triangle(Cursor& c, const Stmt& s) {
  const int at = c.line();
  const std::size_t n = c.count(s, "key count", 19);
  if (n < 1) c.fail(at, "an animated triangle ('tpa') needs at least one key");
  const Node& node = nodes_[stack_.back()];
  TpaTrack& tr = tpa_[{node.context, material()}];
  if (tr.first.empty()) tr.first.push_back(0);
  const auto first_key = tr.times.size();
  std::optional<TpaBackwards> back;  // the first key of this list whose time goes back
  for (std::size_t k = 0; k < n; ++k) {
    const int tline = c.line();
    const double time = c.number(s, "key time");
    if (k > 0 && time < tr.times.back() && !back) back = TpaBackwards{s.line, tline, k, n, time, tr.times.back(), {}};
    tr.reach.push_back(tr.times.size() > first_key ? std::max(tr.reach.back(), time) : time);
    tr.times.push_back(time);
    for (int j = 0; j < 3; ++j) {
      // Affine maps commute with linear interpolation: the enclosing static transforms
      // are applied to the keys once, here.
      tr.corners.push_back(node.to_context.point(c.vec3(s, "vertex " + std::to_string(j))));
      c.vec3(s, "normal " + std::to_string(j));
    }
  }
  tr.first.push_back(static_cast<std::uint32_t>(tr.times.size()));
  note("vertex normals of animated triangles ('tpa') ignored: they move with the keys (flat shading)");
  if (back)  // one warning per file, however many of its triangles do this (see read())
    tpa_backwards_.try_emplace(c.file(), *back).first->second.lists.insert(s.line);
}

void AffReader::sphere(Cursor& c, const Stmt& s) {
  const Vec3d centre = c.vec3(s, "centre");
  const double r = c.number(s, "radius");
  if (r == 0) c.fail(s.line, "sphere radius must not be zero");
  // A negative radius means "inside visible"; shading here is two-sided anyway.
  const std::uint64_t segments = opt_.sphere_segments, rings = opt_.sphere_rings;
  budget_.check(c.file(), "line " + std::to_string(s.line), "this sphere", segments * (rings - 1) + 2,
                2 * segments * (rings - 1));
  Mesh m = uv_sphere(std::fabs(r), opt_.sphere_segments, opt_.sphere_rings);
  for (Vec3d& v : m.vertices) v += centre;
  note("spheres tessellated: " + std::to_string(2 * opt_.sphere_segments * (opt_.sphere_rings - 1)) +
       " triangles each (" + std::to_string(opt_.sphere_segments) + " segments, " +
       std::to_string(opt_.sphere_rings) + " rings)");
  emit(c, s, m);
}

void AffReader::cone(Cursor& c, const Stmt& s) {
  const Vec3d base = c.vec3(s, "base centre");
  double rb = c.number(s, "base radius");
  const Vec3d apex = c.vec3(s, "apex centre");
  double ra = c.number(s, "apex radius");
  if (rb < 0) {  // both negative: inside visible (two-sided shading here)
    rb = -rb;
    ra = -ra;
  }
  if (ra < 0) c.fail(s.line, "cone radii must have the same sign");
  if (rb == 0 && ra == 0) c.fail(s.line, "cone has both radii zero");
  if (dot3(apex - base, apex - base) == 0) c.fail(s.line, "cone base and apex coincide");
  note("cones tessellated: open side surface of " + std::to_string(opt_.cone_segments) + " segments (no caps)");
  budget_.check(c.file(), "line " + std::to_string(s.line), "this cone", 2 * std::uint64_t{opt_.cone_segments},
                2 * std::uint64_t{opt_.cone_segments});
  emit(c, s, cone_mesh(base, rb, apex, ra, opt_.cone_segments));
}

void AffReader::include(Cursor& c, const Stmt& s) {
  const long long level = c.integer(s, "detail level", -1000000, 1000000);
  const std::string name = c.word(s, "a file name");
  if (level > 0) {  // BART includes a file when its level <= the detail level, 0 by default
    note("includes of detail level above 0 skipped (BART's default detail level)");
    return;
  }
  namespace fs = std::filesystem;
  const fs::path p(name);
  const std::string resolved =
      (p.is_absolute() ? p : fs::path(c.file()).parent_path() / p).lexically_normal().string();
  std::error_code ec;
  if (!fs::is_regular_file(resolved, ec))
    c.fail(s.line, "cannot open included file " + shown(name) + " (looked for " +
                       (resolved.size() > 200 ? resolved.substr(0, 200) + "..." : resolved) + ")");
  const std::string key = fs::weakly_canonical(resolved, ec).string();
  for (const std::string& f : including_) {
    if (fs::weakly_canonical(f, ec).string() == key) {
      std::string chain;
      for (const std::string& g : including_) chain += fs::path(g).filename().string() + " -> ";
      c.fail(s.line, "include cycle: " + chain + fs::path(resolved).filename().string());
    }
  }
  if (including_.size() > 64) c.fail(s.line, "includes nested more than 64 deep");
  parse_file(resolved);
}

void AffReader::keyframes(Cursor& c, const Stmt& s) {
  auto a = std::make_shared<Anim>();
  a->name = c.word(s, "an animation name");
  a->file = c.file();
  a->line = s.line;
  const int brace = c.open_brace(s);
  std::set<std::string> seen;
  for (;;) {
    if (c.done()) c.fail(brace, "unterminated '{' of 'k " + a->name + "': no matching '}' before the end of the file");
    const Token kind = c.peek();
    c.skip();
    if (kind.text == "}") break;
    const std::string k(kind.text);
    if (k != "transl" && k != "rot" && k != "scale" && k != "visibility")
      c.fail(kind.line, "unknown keyframe type " + shown(kind.text) + " in 'k " + a->name +
                            "' (expected transl, rot, scale or visibility)");
    if (!seen.insert(k).second) c.fail(kind.line, "'k " + a->name + "' gives '" + k + "' twice");
    const Stmt ks{k, kind.line};
    const std::size_t per = k == "rot" ? 8 : (k == "visibility" ? 2 : 7);
    const int at = c.line();
    const std::size_t n = c.count(ks, "keyframe count", per);
    if (k != "visibility" && n < 4)
      c.fail(at, "'" + k + "' of 'k " + a->name + "' needs at least 4 keyframes (the first and the last only "
                 "shape the curve's ends), found " + std::to_string(n));
    if (k == "visibility" && n < 1) c.fail(at, "'visibility' of 'k " + a->name + "' needs at least 1 keyframe");
    std::vector<double> times;  // as written: BART takes them in any order (see time_quirks)
    std::vector<int> lines;
    auto time = [&]() {
      lines.push_back(c.line());
      times.push_back(c.number(ks, "key time"));
      return times.back();
    };
    auto tcb = [&]() {
      KbParams p;
      p.tension = c.number(ks, "tension");
      p.continuity = c.number(ks, "continuity");
      p.bias = c.number(ks, "bias");
      return p;
    };
    if (k == "transl" || k == "scale") {
      std::vector<KbVecKey> keys(n);
      for (auto& key : keys) {
        key.t = time();
        key.value = c.vec3(ks, k == "transl" ? "translation" : "scale");
        key.tcb = tcb();
      }
      (k == "transl" ? a->transl : a->scale).emplace(keys);
    } else if (k == "rot") {
      std::vector<KbRotKey> keys(n);
      for (auto& key : keys) {
        key.t = time();
        const int al = c.line();
        key.axis = c.vec3(ks, "rotation axis");
        key.degrees = c.number(ks, "rotation angle");
        if (dot3(key.axis, key.axis) == 0 && key.degrees != 0) c.fail(al, "rotation axis is zero");
        key.tcb = tcb();
      }
      a->rot.emplace(keys);
    } else {
      for (std::size_t i = 0; i < n; ++i) {
        const double t = time();
        const int vl = c.line();
        const double v = c.number(ks, "visibility flag");
        if (v != 0 && v != 1) c.fail(vl, "visibility flag must be 0 or 1");
        a->visibility.push_back({t, v != 0});
      }
    }
    time_quirks(c.file(), kind.line, "'" + k + "' keys of 'k " + a->name + "'", times, lines, k == "visibility");
  }
  // The same file included twice (BART's kitchen includes the rear-wheel file again inside
  // each steering front wheel) defines the same keyframes again: that is one definition.
  const auto it = anims_.find(a->name);
  if (it != anims_.end() && it->second->file == a->file && it->second->line == a->line) return;
  if (it != anims_.end())
    c.fail(s.line, "keyframes 'k " + a->name + "' already given at " + it->second->file + " line " +
                       std::to_string(it->second->line));
  anims_[a->name] = a;
}

Scene AffReader::read(const std::string& path) {
  const std::string root = std::filesystem::path(path).lexically_normal().string();
  parse_file(root);

  Scene s;
  s.source = path;
  if (!view_) throw InputError(path, "", "the scene has no view ('v')");
  s.width = view_->width;
  s.height = view_->height;
  s.background = background_;
  s.frame_count = frames_;

  auto find_anim = [&](const std::string& name) -> std::shared_ptr<Anim> {
    const auto it = anims_.find(name);
    return it == anims_.end() ? nullptr : it->second;
  };
  std::set<std::string> used_anims;

  read_camera(s, used_anims);
  read_lights(s, used_anims);

  // Motions of the animated groups, outermost transform first.
  std::map<int, std::vector<Link>> chains;
  chains[0] = {};
  std::function<const std::vector<Link>&(int)> chain = [&](int ctx) -> const std::vector<Link>& {
    auto it = chains.find(ctx);
    if (it != chains.end()) return it->second;
    const Node& n = nodes_[ctx];
    std::vector<Link> c = chain(nodes_[n.parent].context);
    const AnimPtr a = find_anim(n.name);
    if (a) {
      used_anims.insert(n.name);
    } else {
      note("transform 'x " + n.name + "' has no keyframes ('k " + n.name + "'): it stays as placed");
    }
    c.push_back({n.pre, a});
    return chains[ctx] = std::move(c);
  };
  auto motion_of = [&](int ctx) -> MotionPtr {
    const auto& c = chain(ctx);
    bool moves = false, hides = false;
    Affine<double> fixed = Affine<double>::identity();
    for (const Link& l : c) {
      moves = moves || (l.anim && l.anim->moves());
      hides = hides || (l.anim && !l.anim->visibility.empty());
      fixed = fixed * l.pre;
    }
    if (!moves && !hides) return std::make_shared<StaticMotion>(fixed);
    return std::make_shared<AffMotion>(c, clock_);
  };

  // Materials: only those the objects use, in order of first use.
  std::vector<int> mat_remap(materials_.size(), -1);
  auto scene_material = [&](std::uint32_t m) {
    if (mat_remap[m] < 0) {
      mat_remap[m] = static_cast<int>(s.materials.size());
      s.materials.push_back(materials_[m].m);
    }
    return static_cast<std::uint32_t>(mat_remap[m]);
  };
  // A group is named by the path of animated transforms down to it ("toycar/front_wheel_left/
  // rotating_wheel_left"), made unique with "#2", "#3" when a file is included twice; its
  // objects add the material ("/m3") and, when split, the part ("/m3/7").
  std::map<int, std::string> ctx_names{{0, "static"}};
  std::map<std::string, int> ctx_name_count;
  auto context_name = [&](int ctx) -> const std::string& {
    auto it = ctx_names.find(ctx);
    if (it != ctx_names.end()) return it->second;
    std::string path = nodes_[ctx].name;
    for (int p = nodes_[nodes_[ctx].parent].context; p != 0; p = nodes_[nodes_[p].parent].context)
      path = nodes_[p].name + "/" + path;
    const int k = ++ctx_name_count[path];
    if (k > 1) path += "#" + std::to_string(k);
    return ctx_names[ctx] = path;
  };
  auto group_name = [&](int ctx, std::uint32_t m) {
    return context_name(ctx) + "/m" + std::to_string(scene_material(m));
  };

  for (const auto& [key, mesh] : rigid_) {
    const auto [ctx, mat] = key;
    if (mesh.triangles.empty()) continue;
    const MotionPtr motion = motion_of(ctx);
    const auto parts = split_spatially(mesh, opt_.max_object_triangles);
    const std::string base = group_name(ctx, mat);
    for (std::size_t p = 0; p < parts.size(); ++p) {
      Object o;
      o.name = parts.size() == 1 ? base : base + "/" + std::to_string(p);
      o.material = scene_material(mat);
      o.mesh = submesh(mesh, parts[p]);
      o.motion = motion;
      s.objects.push_back(std::move(o));
    }
  }
  for (auto& [key, track] : tpa_) {
    const auto [ctx, mat] = key;
    Object o;
    o.name = group_name(ctx, mat) + "/tpa";
    o.material = scene_material(mat);
    std::vector<Vec3d> rest;
    tpa_corners(track, clock_.time(0), rest);
    o.mesh.vertices = rest;
    for (std::uint32_t k = 0; 3 * k < rest.size(); ++k) o.mesh.triangles.push_back({3 * k, 3 * k + 1, 3 * k + 2});
    o.motion = motion_of(ctx);
    o.deform = std::make_shared<TpaMotion>(std::move(track), clock_);
    s.objects.push_back(std::move(o));
  }
  if (s.materials.empty()) s.materials.push_back(Material{"default", Vec3d(0.7), Vec3d(0.2), 32});

  set_ambient(s, mat_remap);
  note_unused(used_anims);
  s.notes = notes_;
  s.warnings = warnings_;
  validate_scene(s);
  return s;
}

// What the file gave that nothing uses, or that is read as BART reads it.
void AffReader::note_unused(const std::set<std::string>& used_anims) {
  for (const auto& [name, a] : anims_)
    if (!used_anims.count(name)) note("keyframes 'k " + name + "' animate nothing (no 'x " + name + "')");
  warn_tpa_backwards();
  if (flat_normal_triangles_)
    note(std::to_string(flat_normal_triangles_) + " triangles with a zero-length vertex normal: shaded flat");
}

// The view, animated by the keyframes named "camera" if there are any.
void AffReader::read_camera(Scene& s, std::set<std::string>& used_anims) {
  const auto it = anims_.find("camera");
  const AnimPtr cam = it == anims_.end() ? nullptr : it->second;
  if (cam) {
    used_anims.insert("camera");
    if (cam->scale) note("camera 'scale' keyframes ignored");
    if (!cam->visibility.empty()) note("camera 'visibility' keyframes ignored");
  }
  s.camera = cam ? CameraPathPtr(std::make_shared<AffCamera>(view_->camera, cam, clock_))
                 : CameraPathPtr(std::make_shared<FixedCamera>(view_->camera));
}

// An animated light (`la NAME`) is where its keyframes' translation puts it, frame by frame
// (BART: the light sits at the origin of its transform); without translation keys it stays at
// its written position.
void AffReader::read_lights(Scene& s, std::set<std::string>& used_anims) {
  for (const LightDef& l : lights_) {
    PointLight p = l.light;
    if (!l.anim.empty()) {
      const auto it = anims_.find(l.anim);
      const AnimPtr a = it == anims_.end() ? nullptr : it->second;
      if (a) used_anims.insert(l.anim);
      if (a && a->transl) {
        p.position = Vec3d(0);
        p.motion = std::make_shared<AffMotion>(std::vector<Link>{{Affine<double>::identity(), a}}, clock_);
      } else {
        note("animated light '" + l.anim + "' has no translation keys: it stays where it is written");
      }
    }
    s.lights.push_back(p);
  }
}

void AffReader::set_ambient(Scene& s, const std::vector<int>& mat_remap) {
  // Ambient: BART's am x ka as Scene::ambient x kd (see fill()), r the median ka / kd.
  std::vector<double> ratios;
  for (std::size_t m = 0; m < materials_.size(); ++m) {
    if (mat_remap[m] < 0 || !materials_[m].has_ka) continue;
    const Vec3d& ka = materials_[m].ka;
    const Vec3d& kd = materials_[m].m.diffuse;
    const double sd = kd.x + kd.y + kd.z;
    if (sd > 0) ratios.push_back((ka.x + ka.y + ka.z) / sd);
  }
  double r = 1;
  if (!ratios.empty()) {
    std::sort(ratios.begin(), ratios.end());
    r = ratios[ratios.size() / 2];
  }
  bool proportional = true;
  for (std::size_t m = 0; m < materials_.size(); ++m) {
    if (mat_remap[m] < 0 || !materials_[m].has_ka) continue;
    const Vec3d diff = materials_[m].ka - materials_[m].m.diffuse * r;
    if (max_abs_component(diff) > 1e-3 * max_abs_component(materials_[m].ka)) proportional = false;
  }
  s.ambient = ambient_ * r;
  if (!ratios.empty()) {
    std::ostringstream n;
    n << "ambient: BART's am x (material ambient) rendered as (am x " << r
      << ") x diffuse, " << r << " the median ambient/diffuse ratio of the fm materials"
      << (proportional ? " (exact for every material)" : " (approximate for materials with another ratio)");
    note(n.str());
  }

}

void AffReader::warn_tpa_backwards() {
  for (const auto& [file, b] : tpa_backwards_)
    warn(file, b.line, "'tpa' key times go backwards: key " + std::to_string(b.key + 1) + " of " +
                           std::to_string(b.keys) + " (line " + std::to_string(b.key_line) + ") at time " +
                           time_text(b.time) + " after " + time_text(b.after) +
                           (b.lists.size() > 1 ? " (and in " + std::to_string(b.lists.size() - 1) +
                                                     " more 'tpa' of this file)"
                                               : "") +
                           "; read as BART reads them (at time t, from the key before the first key later than t "
                           "to that key)");
}

}  // namespace

Scene load_aff(const std::string& path, const AffOptions& options) {
  AffReader reader(options);
  return reader.read(path);
}

}  // namespace oprt
