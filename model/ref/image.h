// A rendered frame and its files: frame_NNNN.exr (R, G, B, Z as float; objectId, primId
// as uint, 0xFFFFFFFF on a miss) and a PNG preview. Files are written under a temporary
// name and renamed when complete, so a file with the final name is always whole.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace oprt {

struct FrameImage {
  int width = 0, height = 0;
  std::vector<float> r, g, b, z;
  std::vector<std::uint32_t> object, prim;

  FrameImage() = default;
  FrameImage(int w, int h);
  std::size_t size() const { return static_cast<std::size_t>(width) * height; }
  // FNV-1a over every channel's bits: equal hashes, equal images (for golden files).
  std::uint64_t hash() const;
  bool operator==(const FrameImage& o) const;
};

// A pixel a sampled run (--sample) did not trace: R = G = B = 0, Z = NaN, objectId = primId =
// kNotTraced (0xFFFFFFFF stays "no hit").
constexpr std::uint32_t kNotTraced = 0xFFFFFFFEu;
// Marks every pixel but `traced` (frame pixel indices) as not traced; the traced keep their values.
void mark_not_traced(FrameImage& img, const std::vector<std::uint32_t>& traced);

// `sparse`: a sampled frame's (--sample), mostly marks: run-length coded instead of ZIP.
void write_exr(const std::string& path, const FrameImage& img, bool sparse = false);
// Throws InputError (naming the file) if it cannot be read or lacks one of the six channels.
FrameImage read_exr(const std::string& path);
// sRGB-ish preview: clamp to [0, 1], gamma 2.2.
void write_png(const std::string& path, const FrameImage& img);
// The frame's EXR and PNG, written side by side on the pool.
void write_frame_files(const std::string& exr, const std::string& png, const FrameImage& img, bool sparse = false);

// Write `path` through `write(tmp)`: the temporary is renamed to `path` only if write
// returns normally; on an exception it is removed. Throws std::runtime_error on I/O failure.
void write_atomically(const std::string& path, const std::function<void(const std::string& tmp)>& write);
// A temporary name for `path`: hidden, in the same folder (a rename is atomic only within a
// file system), unique per process and per call, so that no two outputs share one.
std::string temporary_path(const std::string& path);

std::string frame_name(int frame, const char* ext);  // frame_0007.exr

}  // namespace oprt
