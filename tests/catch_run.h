#pragma once
// Catch's session, run from a main of our own (catch_main.cpp; hw/hw_main.cpp, SystemC's
// sc_main): Catch's implementation is compiled once, in catch_impl.cpp.
namespace oprt::test {
int run_catch(int argc, char* argv[]);
}  // namespace oprt::test
