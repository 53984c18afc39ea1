// The plain C++ tests' main (Catch's implementation is catch_impl.cpp).
#include "catch_run.h"

int main(int argc, char* argv[]) { return oprt::test::run_catch(argc, argv); }
