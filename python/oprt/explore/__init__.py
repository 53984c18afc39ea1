"""The design-space search behind scripts/explore (docs/explore.md), in modules of one purpose:
common (names and errors), space (the space file), evaluate (one configuration by oprt),
probe (checks before a search), storage (the study's store), study (the search loop), confirm
(references and the front at `at`), outputs (files, plots, summary), cli (the command) and
target (scripts/explore_target: the search against the exhaustive grid)."""
