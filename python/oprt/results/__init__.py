"""The figures and tables of docs/results.md, one module per script of scripts/ (a `main` each,
its usage the module's docstring): bvh (scripts/bvh_results), cache (cache_results), figures
(the paper's Fig. 7, 8, 10), iu (iu_results), level_errors, locality_table, per_iu, plot_route,
profile_levels, route (route_results), scale, score_weights, secondary (secondary_results),
speed_vs_error, top (top_results), trace_cost and waveform_shot."""
