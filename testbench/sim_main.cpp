// SystemC calls sc_main from sc_elab_and_sim(); `oprt render` hands it the prepared run.
#include <functional>

#include <systemc>

namespace oprt {
std::function<int()> g_simulation;
}

int sc_main(int, char*[]) { return oprt::g_simulation ? oprt::g_simulation() : 1; }
