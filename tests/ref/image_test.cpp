#include "ref/image.h"
#include "ref/image_compare.h"
#include "base/error.h"

#include <OpenEXR/ImfRgbaFile.h>

#include <catch2/catch.hpp>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <stdexcept>

using namespace oprt;

TEST_CASE("image: EXR keeps the six channels bit for bit", "[image]") {
  FrameImage img(5, 3);
  for (std::size_t i = 0; i < img.size(); ++i) {
    img.r[i] = 0.1f * i;
    img.g[i] = -1.5f;
    img.b[i] = 1e-30f;
    img.z[i] = i == 4 ? std::numeric_limits<float>::infinity() : 3.25f + i;
    img.object[i] = i == 4 ? 0xFFFFFFFFu : static_cast<std::uint32_t>(i);
    img.prim[i] = static_cast<std::uint32_t>(1000000 + i);
  }
  const auto dir = std::filesystem::temp_directory_path() / "oprt_image_test";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "frame_0000.exr").string();
  write_exr(path, img);
  const FrameImage back = read_exr(path);
  CHECK(back == img);
  CHECK(back.hash() == img.hash());
  img.prim[2] ^= 1;
  CHECK(back.hash() != img.hash());
}

TEST_CASE("image: an interrupted write leaves neither the file nor a temporary", "[image]") {
  const auto dir = std::filesystem::temp_directory_path() / "oprt_atomic_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "out.bin").string();
  CHECK_THROWS(write_atomically(path, [](const std::string& tmp) {
    std::FILE* f = std::fopen(tmp.c_str(), "w");
    std::fputs("half", f);
    std::fclose(f);
    throw std::runtime_error("interrupted");
  }));
  CHECK(std::filesystem::is_empty(dir));
}

TEST_CASE("image: frame names", "[image]") {
  CHECK(frame_name(7, "exr") == "frame_0007.exr");
  CHECK(frame_name(12345, "png") == "frame_12345.png");
}

TEST_CASE("image: every output gets a temporary name of its own, hidden, beside it", "[image]") {
  // Two outputs asked for one path (issue 23, finding 2) must not share a temporary either.
  const std::string a = temporary_path("/x/out/trace.vcd"), b = temporary_path("/x/out/trace.vcd");
  CHECK(a != b);
  CHECK(std::filesystem::path(a).parent_path() == "/x/out");
  CHECK(std::filesystem::path(a).filename().string().rfind(".trace.vcd.tmp", 0) == 0);
}

namespace {
// A 2x2 reference: grey, four pixels, the third a miss.
FrameImage compare_reference() {
  FrameImage ref(2, 2);
  for (std::size_t i = 0; i < 4; ++i) {
    ref.r[i] = ref.g[i] = ref.b[i] = 0.5f;
    if (i == 2) continue;
    ref.z[i] = static_cast<float>(i + 1);  // 1, 2, -, 4
    ref.object[i] = static_cast<std::uint32_t>(i);
    ref.prim[i] = static_cast<std::uint32_t>(10 + i);
  }
  return ref;
}
}  // namespace

TEST_CASE("image compare: hand-computed differences", "[image][compare]") {
  const FrameImage ref = compare_reference();
  const ImageDifference same = compare_images(ref, ref);
  CHECK(same.pixels == 4);
  CHECK(same.id_mismatches == 0);
  CHECK(same.color_rmse == 0);
  CHECK(same.max_rel_z == 0);
  CHECK(same.z_compared == 3);

  FrameImage a = ref;
  a.prim[1] = 12;     // another triangle of the same object
  a.z[1] = 2.5f;      // |2.5 - 2| / 2 = 0.25
  a.r[1] = 1.0f;      // colour error 0.5
  a.object[2] = 2;    // hits where the reference misses: an id mismatch, no Z to compare
  a.prim[2] = 5;
  a.z[2] = 3;
  a.z[3] = 4.5f;      // 0.125
  a.g[3] = 0.25f;     // colour error 0.25
  const ImageDifference d = compare_images(a, ref);
  CHECK(d.pixels == 4);
  CHECK(d.id_mismatches == 2);
  CHECK(d.z_compared == 3);
  CHECK(d.max_rel_z == Approx(0.25));
  // sqrt((0.5^2 + 0.25^2) / (3 channels x 4 pixels))
  CHECK(d.color_rmse == Approx(std::sqrt(0.3125 / 12)));
}

TEST_CASE("image compare: sizes must match, unreadable files name themselves", "[image][compare]") {
  CHECK_THROWS_AS(compare_images(FrameImage(2, 2), FrameImage(2, 3)), std::invalid_argument);
  const auto dir = std::filesystem::temp_directory_path() / "oprt_compare_test";
  std::filesystem::create_directories(dir);
  const std::string text = (dir / "not.exr").string();
  std::FILE* f = std::fopen(text.c_str(), "w");
  std::fputs("not an image", f);
  std::fclose(f);
  try {
    read_exr(text);
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(e.file() == text);
    CHECK(e.problem().find("cannot read as OpenEXR") != std::string::npos);
  }
  // An EXR without the oprt channels (a plain RGBA picture).
  const std::string rgba = (dir / "rgba.exr").string();
  {
    Imf::Rgba px[4];
    Imf::RgbaOutputFile out(rgba.c_str(), 2, 2, Imf::WRITE_RGBA);
    out.setFrameBuffer(px, 1, 2);
    out.writePixels(2);
  }
  try {
    read_exr(rgba);
    FAIL("no error");
  } catch (const InputError& e) {
    CHECK(e.file() == rgba);
    CHECK(e.place() == "channel Z");
  }
}
