#!/usr/bin/env bash
# scripts/fuzz builds with clang, C and C++, where gcc is the default compiler and even over a
# build folder configured with gcc before (issue 23, finding 13: -fsanitize=fuzzer-no-link on
# fstapi's C files failed). Skipped (77) where clang or its libFuzzer runtime is not
# installed (scripts/setup fuzz).
#   test_fuzz_build.sh SOURCE_DIR BUILD_DIR
set -euo pipefail
src=$1 build=$2
for p in clang libclang-rt-14-dev; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" ||
    { echo "$p is not installed (scripts/setup fuzz): skipped"; exit 77; }
done
rm -rf "$build"
cd "$src"
CC=gcc CXX=g++ cmake -S . -B "$build" -G Ninja -DBUILD_TESTING=OFF >/dev/null  # a build folder gcc configured
CC=gcc CXX=g++ OPRT_FUZZ_BUILD="$build" scripts/fuzz --configure
grep -E "^CMAKE_C_COMPILER:[A-Z]*=.*clang$" "$build/CMakeCache.txt"
grep -E "^CMAKE_CXX_COMPILER:[A-Z]*=.*clang\+\+$" "$build/CMakeCache.txt"
cmake --build "$build" --target fstapi  # the C files, with libFuzzer's flags
rm -rf "$build"
