// Small scenes built in code for the reference and model tests, with the geometry laid out
// so that expected hits, distances and shadows can be worked out by hand.
#pragma once

#include "scene/scene.h"

namespace oprt::test {

// Camera at (0, 0, 10) looking down -z, fov 90 (tan = 1), square image. A 20x20 wall in the
// z = 0 plane (object 0, two triangles, diffuse 0.8 grey), a 1x1 occluder square centred at
// (4, 0, 5) facing +z (object 1), ambient 0.1, one light at (10, 0, 10).
// The occluder's shadow on the wall, projected from the light: x in [-3, -1], y in [-1, 1].
inline Scene shadow_box(int size = 64) {
  Scene s;
  s.source = "shadow_box (built in code)";
  s.width = s.height = size;
  Camera c;
  c.eye = {0, 0, 10};
  c.target = {0, 0, 0};
  c.up = {0, 1, 0};
  c.fov_y_deg = 90;
  s.camera = std::make_shared<FixedCamera>(c);
  s.ambient = Vec3d(0.1);
  s.background = Vec3d(0);
  s.lights.push_back({{10, 0, 10}, Vec3d(1), nullptr});
  s.materials.push_back({"grey", Vec3d(0.8), Vec3d(0), 1});
  auto quad = [](double cx, double cy, double cz, double half) {
    Mesh m;
    m.vertices = {{cx - half, cy - half, cz}, {cx + half, cy - half, cz}, {cx + half, cy + half, cz},
                  {cx - half, cy + half, cz}};
    m.triangles = {{0, 1, 2}, {0, 2, 3}};
    return m;
  };
  Object wall{"wall", 0, quad(0, 0, 0, 10), std::make_shared<StaticMotion>(Affine<double>::identity()), nullptr};
  Object occ{"occluder", 0, quad(4, 0, 5, 0.5), std::make_shared<StaticMotion>(Affine<double>::identity()), nullptr};
  s.objects.push_back(wall);
  s.objects.push_back(occ);
  return s;
}

}  // namespace oprt::test
