"""oprt's Python package: what the scripts in scripts/ share, importable from a notebook.

    import sys; sys.path.insert(0, "/path/to/oprt/python")
    from oprt import render
    stats = render.render(["scenes/paper_room.json", "--frames", "0", "--resolution", "64x64"], "out/room")
    print(stats["frames"][0]["makespan_cycles"])

Modules, one purpose each:
- oprt.paths: the repository's folders and the oprt binary a script uses by default;
- oprt.render: running `oprt render` and `oprt reference` (and children that end with their parent);
- oprt.rays: a frame's figures per ray kind (primary, shadow, reflection, refraction), work priced per kind;
- oprt.stats: reading stats.json and stats.csv, and the correlation the result scripts print;
- oprt.pareto: Pareto fronts and hypervolumes (minimised objectives);
- oprt.slurm: Slurm array-job scripts;
- oprt.plots: matplotlib set up for files (and installed on first use), shared plot styles;
- oprt.files: atomic writes (a killed process never leaves half a file);
- oprt.spec: sweep specification values (shared by scripts/sweep and scripts/explore);
- oprt.explore: the design-space search behind scripts/explore.
"""
