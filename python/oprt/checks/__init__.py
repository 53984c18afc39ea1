"""Checks that a change moved no figure, one module per script: golden (the regression figures
of tests/golden), compare_builds (two builds' outputs byte for byte) and simd_check (the SIMD
kernels against the scalar ones)."""
