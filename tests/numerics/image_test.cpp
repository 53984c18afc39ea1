// Issue 6's image-level check: a closed mesh placed far from the origin (1e5), rendered in
// float with the watertight kernel, shows no background pixel inside its silhouette (judged
// by a double-precision oracle on the camera rays, hard_cases.cpp), and no pixel of its far
// side either: a ray that leaks through the front of a closed mesh usually hits the back,
// so the background test alone would rarely see a leak.
#include "hard_cases.h"

#include <catch2/catch.hpp>

using namespace oprt;
using namespace oprt::numerics;

TEST_CASE("image: a closed mesh far from the origin has no hole in float with the watertight kernel",
          "[numerics][image]") {
  for (bool in_coordinates : {false, true}) {
    const ImageCheck c = image_check(Kernel::watertight, false, in_coordinates, 128);
    INFO((in_coordinates ? "placed in its coordinates: " : "placed by its transform: ")
         << c.background_inside << " background pixels of " << c.inside_pixels << " inside the silhouette");
    CHECK(c.inside_pixels > 128 * 128 / 4);  // the meshes fill a good part of the frame
    CHECK(c.background_inside == 0);
    INFO(c.see_through << " pixels show the far side");
    CHECK(c.see_through == 0);  // nor a leak through the front that the back side hides
  }
}

TEST_CASE("image: the check has teeth - Moller-Trumbore in float shows the far side through its front",
          "[numerics][image]") {
  // With the placement in the vertex coordinates, Moller's stored v0 and edges round
  // separately per triangle, so neighbours disagree on their shared vertices.
  const ImageCheck c = image_check(Kernel::moller, false, true, 256);
  CHECK(c.inside_pixels > 256 * 256 / 8);
  CHECK(c.see_through + c.background_inside > 0);
}
