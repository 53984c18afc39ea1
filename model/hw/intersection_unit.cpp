#include "hw/intersection_unit.h"

namespace oprt::hw {



using namespace sc_core;

template <typename T>
IntersectionUnit<T>::IntersectionUnit(const sc_module_name& name, int id, const Arch& arch,
                                      const SceneGeometry<T>& geometry, const FunctionalFrame<T>& frame)
    : sc_module(name),
      cfg("cfg"),
      bus("bus"),
      mem("mem"),
      fifo("fifo"),
      id_(id),
      arch_(arch),
      geom_(geometry),
      frame_(frame),
      cycle_(arch.cycle_ns(), SC_NS) {
  cfg.register_b_transport(this, &IntersectionUnit::cfg_transport);
}

template <typename T>
void IntersectionUnit<T>::cfg_transport(tlm::tlm_generic_payload& p, sc_time&) {
  const auto* c = extension_of<ConfigExtension<T>>(p);
  if (p.get_command() != tlm::TLM_WRITE_COMMAND || p.get_address() != 0) {
    p.set_response_status(tlm::TLM_ADDRESS_ERROR_RESPONSE);
    return;
  }
  if (!c || !c->registers) {
    p.set_response_status(tlm::TLM_GENERIC_ERROR_RESPONSE);
    return;
  }
  regs_ = *c->registers;
  cached_ = c->cached;
  p.set_response_status(tlm::TLM_OK_RESPONSE);
}

template <typename T>
void IntersectionUnit<T>::send_answer(std::uint32_t ray, const UnitRayWork* w, sc_time& delay) {
  const auto unit = static_cast<std::uint32_t>(id_);
  const UnitAnswer<T> answer = frame_.answer(w, unit);
  WireAnswer<T> a;
  a.ray = ray;
  a.unit = unit;
  a.occluded = answer.occluded;
  a.hit = answer.hit;
  unsigned char* data = answer_bytes_.data(Bytes<T>::nearest_answer);
  const unsigned bytes = a.write(data, seeks_nearest(frame_.rays[ray].kind));
  prepare(answer_, tlm::TLM_WRITE_COMMAND, addr::gpp_hits, data, bytes);
  bus->b_transport(answer_, delay);
  if (answer_.is_response_error()) SC_REPORT_FATAL(name(), "answer to the GPP failed");
}

template <typename T>
Cycle IntersectionUnit<T>::read(std::uint32_t sphere, std::uint64_t bytes, const VisitStream* stream,
                                BurstConsumer* unit, Cycle request, bool sync, Cycle horizon) {
  VisitReadExtension& e = prepare<VisitReadExtension>(read_, tlm::TLM_READ_COMMAND, 0, read_bytes_.data(bytes),
                                                      static_cast<unsigned>(bytes));
  e.sphere = sphere;
  e.stream = stream;
  e.unit = unit;
  e.sync = sync;
  e.horizon = horizon;
  const sc_time at = time_of(request);
  sc_time delay = at > sc_time_stamp() ? at - sc_time_stamp() : SC_ZERO_TIME;
  mem->b_transport(read_, delay);
  if (read_.is_response_error())
    SC_REPORT_FATAL(name(), ("object memory does not hold sphere " + std::to_string(sphere)).c_str());
  return cycle_of(sc_time_stamp() + delay);
}

template <typename T>
std::string IntersectionUnit<T>::its_fifo() const {
  const auto* f = dynamic_cast<const sc_object*>(fifo.get_interface());
  return "its FIFO " + std::string(f ? f->name() : "?") + " " + fifo->fill_state();
}

template <typename T>
std::string IntersectionUnit<T>::waiting_for() const {
  switch (activity_) {
    case Activity::waiting_for_ray: return "waiting for a ray; " + its_fifo();
    case Activity::tracing: return "tracing ray " + std::to_string(ray_) + "; " + its_fifo();
    case Activity::answering: return "waiting for the bus to take its answer to ray " + std::to_string(ray_) + "; " + its_fifo();
    case Activity::waiting_for_slot: return "every ray slot holds a ray whose answer has not left; " + its_fifo();
  }
  return its_fifo();
}

template class IntersectionUnit<float>;
template class IntersectionUnit<double>;

}  // namespace oprt::hw
