// Catch's implementation, compiled once for every test executable: the plain C++ tests link it
// with catch_main.cpp, the SystemC tests with hw/hw_main.cpp (sc_main).
#define CATCH_CONFIG_RUNNER
#include <catch2/catch.hpp>

#include "catch_run.h"

int oprt::test::run_catch(int argc, char* argv[]) { return Catch::Session().run(argc, argv); }
