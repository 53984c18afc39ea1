#include "ref/image.h"

#include <catch2/catch.hpp>

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
