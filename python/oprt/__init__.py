"""oprt's Python package: the logic of the scripts in scripts/ (each a few lines calling a
module's `main`), importable from a notebook once installed (README, "From Python"):

    python3 -m venv --system-site-packages v && v/bin/pip install --no-build-isolation --no-index ./python
    v/bin/python -c 'from oprt import pareto; print(pareto.hypervolume([(1, 2), (2, 1)], (3, 3)))'  # 3.0

`cmake --install build --prefix DIR` installs it too, into DIR/lib/python3/dist-packages.

Shared modules, one purpose each:
- oprt.paths: the repository's folders and the oprt binary a script uses by default;
- oprt.render: running `oprt render` and `oprt reference` (and children that end with their parent);
- oprt.rays: a frame's figures per ray kind (primary, shadow, reflection, refraction), work priced per kind;
- oprt.stats: reading stats.json and stats.csv, and the correlation the result scripts print;
- oprt.pareto: Pareto fronts and hypervolumes (minimised objectives);
- oprt.slurm: Slurm array-job scripts;
- oprt.plots: matplotlib set up for files (and installed on first use), shared plot styles;
- oprt.files: atomic writes (a killed process never leaves half a file);
- oprt.spec: sweep specification values (shared by scripts/sweep and scripts/explore);
- oprt.values: small helpers for values read from JSON and shown to people.

The tools, a module (or package) per script:
- oprt.sweep: scripts/sweep (points, run, aggregate, cli) and scripts/plot_sweep (plot);
- oprt.explore: the design-space search behind scripts/explore (cli) and scripts/explore_target (target);
- oprt.results: the tables and figures of docs/results.md (bvh_results, cache_results, figures, ...);
- oprt.checks: golden, compare_builds and simd_check (a change moved no figure);
- oprt.mutate: the mutation check behind scripts/mutate;
- oprt.scenes: the paper's two scenes (scripts/make_paper_scenes).
"""
