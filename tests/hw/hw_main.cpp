// The SystemC tests' runner: SystemC calls sc_main, which hands over to Catch. ctest runs
// each test case in its own process (SystemC elaborates once per process). A SystemC
// warning or error fails the test. Catch's implementation is catch_impl.cpp.
#include "catch_run.h"

#include <systemc>

int sc_main(int argc, char* argv[]) {
  sc_core::sc_report_handler::set_actions(sc_core::SC_WARNING, sc_core::SC_DISPLAY | sc_core::SC_THROW);
  sc_core::sc_report_handler::set_actions(sc_core::SC_ERROR, sc_core::SC_DISPLAY | sc_core::SC_THROW);
  sc_core::sc_report_handler::set_actions(sc_core::SC_FATAL, sc_core::SC_DISPLAY | sc_core::SC_THROW);
  sc_core::sc_report_handler::set_actions("/OSCI/SystemC", sc_core::SC_INFO, sc_core::SC_DO_NOTHING);
  return oprt::test::run_catch(argc, argv);
}
