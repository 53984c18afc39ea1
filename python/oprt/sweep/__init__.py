"""Architecture-exploration sweeps over `oprt render` (docs/sweeps.md): points (the SPEC read
and expanded), run (each point one oprt process, checked first), aggregate (aggregate.csv,
status.csv, summary.md), cli (scripts/sweep) and plot (scripts/plot_sweep)."""
