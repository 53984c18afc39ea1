// What crosses the bus and the units' memory ports, and where it goes.
//
// Every transaction is a TLM-2.0 generic payload whose data pointer and data length describe
// bytes: data_length is what the hardware moves (the bus and the memories time it), and the
// data pointer points at a buffer that really holds that many bytes (IEEE 1666 14.13):
//  - small items carry their real contents, serialised as the hardware lays them out
//    (WireRay, WireAnswer): a ray FIFO takes the ray's id from its bytes, the GPP reads
//    each answer from its bytes;
//  - bulk transfers (configuration registers, geometry loads, a visit's reads, cache line
//    fills) point at a buffer of the right length whose contents are not modelled: the
//    values are the frame set-up's and the geometry's, which the model keeps once
//    (functional_frame.h, SceneGeometry) instead of copying them into every transfer.
// What a target needs beyond those bytes rides in an extension (IEEE 1666 14.2), set by the
// initiator and read with get_extension: the registers' typed form, which spheres a load
// holds, how a unit consumes a visit's bursts. A target that needs an extension and finds
// none answers TLM_GENERIC_ERROR_RESPONSE. Each initiator keeps a payload per purpose, and
// the payload owns its extension (every transaction here is blocking: no memory manager).
#pragma once

#include "ref/bytes.h"
#include "timing/cycle.h"
#include "timing/frame_command.h"
#include "timing/object_memory_model.h"
#include "ref/traverse.h"

#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>

#include <tlm>

namespace oprt::hw {

using timing::BurstConsumer, timing::Cycle, timing::FrameCommand, timing::MemoryLoad, timing::VisitStream;

// Bus address map. Each unit i owns a window at iu_base + i * iu_stride.
namespace addr {
constexpr std::uint64_t gpp_hits = 0x0400'0000;        // answers from the units
constexpr std::uint64_t broadcast_rays = 0x0800'0000;  // a ray written here enters every FIFO
// --route, transfer "mask": the ray's bytes, then a unit mask (one bit per unit): it enters
// the FIFOs of the units the mask names.
constexpr std::uint64_t multicast_rays = 0x0900'0000;
constexpr std::uint64_t region_size = 0x1000;
constexpr std::uint64_t iu_base = 0x1000'0000;
constexpr std::uint64_t iu_stride = 0x0100'0000;
constexpr std::uint64_t iu_config = 0x0000'0000;       // + configuration registers
constexpr std::uint64_t iu_memory = 0x0040'0000;       // + object memory load window
constexpr std::uint64_t iu_ray_fifo = 0x0080'0000;     // + this unit's ray FIFO only
constexpr std::uint64_t iu_window(int unit) { return iu_base + static_cast<std::uint64_t>(unit) * iu_stride; }
// DRAM: the scene's geometry (timing/visit_stream.h GeometryAddresses) from dram_base on;
// cache line fills read it (directly from a channel, or over the bus).
constexpr std::uint64_t dram_base = 0x1'0000'0000;
constexpr std::uint64_t dram_size = std::uint64_t{1} << 40;
}  // namespace addr

// A grow-only byte buffer, zeroed by calloc: pages of a large bulk buffer that nothing
// reads are never touched.
class ByteBuffer {
 public:
  unsigned char* data(std::size_t bytes) {
    if (bytes > size_) {
      p_.reset(static_cast<unsigned char*>(std::calloc(bytes, 1)));
      if (!p_) throw std::bad_alloc();
      size_ = bytes;
    }
    return p_.get();
  }

 private:
  struct Free {
    void operator()(unsigned char* p) const { std::free(p); }
  };
  std::unique_ptr<unsigned char, Free> p_;
  std::size_t size_ = 0;
};

// A ray as the bus and the FIFOs carry it: id, kind, origin, direction, extent (and with
// --top bvh its reciprocal direction).
template <typename T>
struct WireRay {
  static void write(unsigned char* out, std::uint32_t id, const RayRecord<T>& r, bool reciprocal) {
    const std::uint32_t kind = static_cast<std::uint32_t>(r.kind);
    std::memcpy(out, &id, 4);
    std::memcpy(out + 4, &kind, 4);
    const T v[7] = {r.ray.o.x, r.ray.o.y, r.ray.o.z, r.ray.d.x, r.ray.d.y, r.ray.d.z, r.ray.tmax};
    std::memcpy(out + 8, v, sizeof v);
    if (reciprocal) {
      const T inv[3] = {T(1) / r.ray.d.x, T(1) / r.ray.d.y, T(1) / r.ray.d.z};
      std::memcpy(out + 8 + sizeof v, inv, sizeof inv);
    }
  }
  static std::uint32_t id(const unsigned char* in) {
    std::uint32_t id;
    std::memcpy(&id, in, 4);
    return id;
  }
};

// A unit's answer as it crosses the bus: ray, unit, flags; for a nearest-hit ray also
// object, primitive and t, u, v (Bytes<T>::nearest_answer), else 12 bytes.
template <typename T>
struct WireAnswer {
  std::uint32_t ray = 0, unit = 0;
  bool occluded = false;
  HitRecord<T> hit;

  unsigned write(unsigned char* out, bool nearest) const {
    const std::uint32_t flags = (occluded ? 1u : 0u) | (hit.valid() ? 2u : 0u);
    std::memcpy(out, &ray, 4);
    std::memcpy(out + 4, &unit, 4);
    std::memcpy(out + 8, &flags, 4);
    if (!nearest) return Bytes<T>::shadow_answer;
    std::memcpy(out + 12, &hit.object, 4);
    std::memcpy(out + 16, &hit.prim, 4);
    const T v[3] = {hit.t, hit.u, hit.v};
    std::memcpy(out + 20, v, sizeof v);
    return Bytes<T>::nearest_answer;
  }
  // Reads what write() wrote; false if `bytes` is neither answer's size.
  bool read(const unsigned char* in, unsigned bytes) {
    if (bytes != Bytes<T>::shadow_answer && bytes != Bytes<T>::nearest_answer) return false;
    std::uint32_t flags;
    std::memcpy(&ray, in, 4);
    std::memcpy(&unit, in + 4, 4);
    std::memcpy(&flags, in + 8, 4);
    occluded = flags & 1u;
    hit = HitRecord<T>{};
    if (bytes == Bytes<T>::nearest_answer && (flags & 2u)) {
      std::memcpy(&hit.object, in + 12, 4);
      std::memcpy(&hit.prim, in + 16, 4);
      T v[3];
      std::memcpy(v, in + 20, sizeof v);
      hit.t = v[0], hit.u = v[1], hit.v = v[2];
    }
    return true;
  }
};

// The CRTP boilerplate of an extension that the initiator owns and the target only reads.
template <typename E>
struct Extension : tlm::tlm_extension<E> {
  tlm::tlm_extension_base* clone() const override { return new E(static_cast<const E&>(*this)); }
  void copy_from(const tlm::tlm_extension_base& other) override { static_cast<E&>(*this) = static_cast<const E&>(other); }
};

// Configuration registers: the unit's registers for the frame, in the typed form the model
// tests rays with (data_length: Bytes<T>::sphere_config per sphere and top_node per node).
template <typename T>
struct ConfigExtension : Extension<ConfigExtension<T>> {
  const IuRegisters<T>* registers = nullptr;
  bool cached = false;  // its object memory is a cache (its spheres do not fit): time visits through it
};

// A geometry load into an object memory (data_length: the bytes written; 0 for a memory
// that becomes a cache: DRAM holds the geometry).
struct LoadExtension : Extension<LoadExtension> {
  const MemoryLoad* load = nullptr;
};

// A unit's reads of one sphere visit from its object memory (data_length: the triangles' and
// nodes' bytes). With a stream the memory times the visit's bursts (object_memory_model.h)
// and hands their arrivals to the unit's consumer; the annotated delay is the first
// burst's request, and on return the unit's end of the visit. Without one the reads are
// on-chip memory's, whose time the functional trace already holds.
struct VisitReadExtension : Extension<VisitReadExtension> {
  std::uint32_t sphere = 0;                 // the sphere read; kNone: several spheres of one ray
  const VisitStream* stream = nullptr;
  BurstConsumer* unit = nullptr;
  bool sync = false;  // wait until each miss is due before sending it (DRAM sees requests in time order)
  Cycle horizon = 0;  // no later read of this unit's asks for anything before (its timing state's past)
};

// A cache line fill (data_length: line_bytes; address: addr::dram_base + the line's address).
struct FillExtension : Extension<FillExtension> {
  std::uint32_t unit = 0;  // whose memory: its DRAM channel
};

// The host's frame command.
struct FrameExtension : Extension<FrameExtension> {
  FrameCommand* command = nullptr;
};

// Sets a payload up for a blocking transaction (a payload serves one purpose, so the
// extension it carries, if any, is always of one type).
inline void prepare(tlm::tlm_generic_payload& p, tlm::tlm_command cmd, std::uint64_t address, unsigned char* data,
                    unsigned length) {
  p.set_command(cmd);
  p.set_address(address);
  p.set_data_ptr(data);
  p.set_data_length(length);
  p.set_streaming_width(length);
  p.set_byte_enable_ptr(nullptr);
  p.set_dmi_allowed(false);
  p.set_response_status(tlm::TLM_INCOMPLETE_RESPONSE);
}
// ... with an extension of type E, returned to be filled in. The payload owns it (its
// destructor frees it, IEEE 1666 14.21), created at the first use.
template <typename E>
E& prepare(tlm::tlm_generic_payload& p, tlm::tlm_command cmd, std::uint64_t address, unsigned char* data,
           unsigned length) {
  prepare(p, cmd, address, data, length);
  E* e = nullptr;
  p.get_extension(e);
  if (!e) {
    e = new E;
    p.set_extension(e);
  }
  return *e;
}
// The payload's extension of type E, or null.
template <typename E>
E* extension_of(tlm::tlm_generic_payload& p) {
  E* e = nullptr;
  p.get_extension(e);
  return e;
}

}  // namespace oprt::hw
