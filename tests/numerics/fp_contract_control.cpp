// The control for fp_contract_test.cpp, compiled with -ffp-contract=fast (tests/CMakeLists.txt):
// the expression of dot3 (geom/vec.h) written out, so that the compiler may fuse it. It
// shares no inline function with the rest of the build (that would break the one-definition
// rule across different flags).
namespace oprt::fp_control {

float dot_xy_contractible(float ax, float ay, float bx, float by) { return ax * bx + ay * by; }

bool fma_available() {
#ifdef __FMA__
  return true;
#else
  return false;
#endif
}

}  // namespace oprt::fp_control
