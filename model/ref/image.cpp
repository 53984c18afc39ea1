#include "ref/image.h"
#include "ref/parallel.h"

#include "base/error.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfInputFile.h>
#include <OpenEXR/ImfOutputFile.h>
#include <OpenEXR/ImfThreading.h>

#include <stb_image_write.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <stdexcept>
#include <unistd.h>

namespace oprt {

void mark_not_traced(FrameImage& img, const std::vector<std::uint32_t>& traced) {
  std::vector<char> keep(img.size(), 0);
  for (std::uint32_t p : traced) keep[p] = 1;
  for (std::size_t p = 0; p < img.size(); ++p) {
    if (keep[p]) continue;
    img.r[p] = img.g[p] = img.b[p] = 0;
    img.z[p] = std::numeric_limits<float>::quiet_NaN();
    img.object[p] = img.prim[p] = kNotTraced;
  }
}

FrameImage::FrameImage(int w, int h) : width(w), height(h) {
  const std::size_t n = size();
  r.assign(n, 0);
  g.assign(n, 0);
  b.assign(n, 0);
  z.assign(n, std::numeric_limits<float>::infinity());
  object.assign(n, 0xFFFFFFFFu);
  prim.assign(n, 0xFFFFFFFFu);
}

std::uint64_t FrameImage::hash() const {
  std::uint64_t h = 1469598103934665603ULL;
  auto mix = [&](const void* data, std::size_t bytes) {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < bytes; ++i) h = (h ^ p[i]) * 1099511628211ULL;
  };
  mix(&width, sizeof width);
  mix(&height, sizeof height);
  for (const auto* c : {&r, &g, &b, &z}) mix(c->data(), c->size() * sizeof(float));
  for (const auto* c : {&object, &prim}) mix(c->data(), c->size() * sizeof(std::uint32_t));
  return h;
}

bool FrameImage::operator==(const FrameImage& o) const {
  auto same = [](const std::vector<float>& a, const std::vector<float>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
  };
  return width == o.width && height == o.height && same(r, o.r) && same(g, o.g) && same(b, o.b) &&
         same(z, o.z) && object == o.object && prim == o.prim;
}

std::string frame_name(int frame, const char* ext) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "frame_%04d.%s", frame, ext);
  return buf;
}

std::string temporary_path(const std::string& path) {
  static std::atomic<unsigned> next{0};
  const std::filesystem::path p(path);
  return (p.parent_path() / ("." + p.filename().string() + ".tmp" + std::to_string(::getpid()) + "." +
                             std::to_string(next++)))
      .string();
}

void write_atomically(const std::string& path, const std::function<void(const std::string&)>& write) {
  namespace fs = std::filesystem;
  const fs::path target(path);
  const fs::path tmp = temporary_path(path);
  try {
    write(tmp.string());
    fs::rename(tmp, target);
  } catch (...) {
    std::error_code ec;
    fs::remove(tmp, ec);
    throw;
  }
}

namespace {
// Below this many pixels an image is written on the calling thread: handing it to the pool
// (parallel_chunks starts a thread per call, and each thread may take a malloc arena of its
// own) costs more than it saves, and a run of tiny frames would grow its memory.
constexpr std::size_t kParallelPixels = std::size_t{1} << 16;
int exr_threads() {
  static const int threads = [] {
    const int n = thread_count();
    if (n > 1) Imf::setGlobalThreadCount(n);
    return n > 1 ? n : 0;
  }();
  return threads;
}
}  // namespace

void write_exr(const std::string& path, const FrameImage& img, bool sparse) {
  write_atomically(path, [&](const std::string& tmp) {
    Imf::Header header(img.width, img.height);
    // A sampled frame's image is mostly the mark of pixels not traced: runs of equal bytes,
    // which run-length coding takes as well as ZIP does, several times faster.
    header.compression() = sparse ? Imf::RLE_COMPRESSION : Imf::ZIP_COMPRESSION;
    for (const char* c : {"R", "G", "B", "Z"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    for (const char* c : {"objectId", "primId"}) header.channels().insert(c, Imf::Channel(Imf::UINT));
    Imf::FrameBuffer fb;
    const std::size_t fs = sizeof(float), us = sizeof(std::uint32_t);
    auto slice_f = [&](const char* name, const std::vector<float>& v) {
      fb.insert(name, Imf::Slice(Imf::FLOAT, (char*)v.data(), fs, fs * img.width));
    };
    slice_f("R", img.r);
    slice_f("G", img.g);
    slice_f("B", img.b);
    slice_f("Z", img.z);
    fb.insert("objectId", Imf::Slice(Imf::UINT, (char*)img.object.data(), us, us * img.width));
    fb.insert("primId", Imf::Slice(Imf::UINT, (char*)img.prim.data(), us, us * img.width));
    // OpenEXR compresses the file's blocks of scanlines on its own thread pool, as many
    // threads as the functional work may use (the bytes do not depend on how many).
    const int threads = img.size() < kParallelPixels ? 0 : exr_threads();
    Imf::OutputFile file(tmp.c_str(), header, threads);
    file.setFrameBuffer(fb);
    file.writePixels(img.height);
  });
}

namespace {
FrameImage read_exr_or_throw(const std::string& path) {
  Imf::InputFile file(path.c_str());
  for (const char* c : {"R", "G", "B", "Z", "objectId", "primId"})
    if (!file.header().channels().findChannel(c))
      throw InputError(path, std::string("channel ") + c, "missing (an oprt frame has R, G, B, Z, objectId, primId)");
  const auto dw = file.header().dataWindow();
  FrameImage img(dw.max.x - dw.min.x + 1, dw.max.y - dw.min.y + 1);
  Imf::FrameBuffer fb;
  const std::size_t fs = sizeof(float), us = sizeof(std::uint32_t);
  const std::ptrdiff_t origin = -(static_cast<std::ptrdiff_t>(dw.min.y) * img.width + dw.min.x);
  auto slice_f = [&](const char* name, std::vector<float>& v) {
    fb.insert(name, Imf::Slice(Imf::FLOAT, (char*)(v.data() + origin), fs, fs * img.width));
  };
  slice_f("R", img.r);
  slice_f("G", img.g);
  slice_f("B", img.b);
  slice_f("Z", img.z);
  fb.insert("objectId", Imf::Slice(Imf::UINT, (char*)(img.object.data() + origin), us, us * img.width));
  fb.insert("primId", Imf::Slice(Imf::UINT, (char*)(img.prim.data() + origin), us, us * img.width));
  file.setFrameBuffer(fb);
  file.readPixels(dw.min.y, dw.max.y);
  return img;
}
}  // namespace

FrameImage read_exr(const std::string& path) {
  require_regular_file(path);  // a pipe would block the reader forever, a device never end
  try {
    return read_exr_or_throw(path);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {  // OpenEXR's: missing, truncated, not an EXR
    throw InputError(path, "", std::string("cannot read as OpenEXR: ") + e.what());
  }
}

void write_png(const std::string& path, const FrameImage& img) {
  std::vector<unsigned char> rgb(img.size() * 3);
  auto gamma = [](float x) {
    const double c = std::clamp(static_cast<double>(x), 0.0, 1.0);
    if (c == 0) return static_cast<unsigned char>(0);  // what pow gives, without it (black: sampled frames' marks)
    return static_cast<unsigned char>(std::lround(std::pow(c, 1 / 2.2) * 255));
  };
  auto encode = [&](std::size_t, std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      rgb[3 * i] = gamma(img.r[i]);
      rgb[3 * i + 1] = gamma(img.g[i]);
      rgb[3 * i + 2] = gamma(img.b[i]);
    }
  };
  if (img.size() < kParallelPixels) encode(0, 0, img.size());
  else parallel_chunks(img.size(), 1 << 14, encode);
  write_atomically(path, [&](const std::string& tmp) {
    if (!stbi_write_png(tmp.c_str(), img.width, img.height, 3, rgb.data(), img.width * 3))
      throw std::runtime_error("cannot write " + path);
  });
}

// Both at once: the PNG's deflate is one thread's work, the EXR's blocks are compressed on
// OpenEXR's pool beside it.
void write_frame_files(const std::string& exr, const std::string& png, const FrameImage& img, bool sparse) {
  if (img.size() < kParallelPixels) {
    write_exr(exr, img, sparse);
    write_png(png, img);
    return;
  }
  parallel_chunks(2, 1, [&](std::size_t c, std::size_t, std::size_t) {
    if (c == 0) write_exr(exr, img, sparse);
    else write_png(png, img);
  });
}

}  // namespace oprt
