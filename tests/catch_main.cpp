// The plain C++ tests' main (Catch's implementation is catch_impl.cpp).
#include <catch2/catch.hpp>

int main(int argc, char* argv[]) { return Catch::Session().run(argc, argv); }
