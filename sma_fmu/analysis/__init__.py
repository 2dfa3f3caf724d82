"""Analysis of what tracking is possible at all (numpy; not shipped in the FMUs).

- :mod:`~sma_fmu.analysis.tracking_problem`: a scenario's reference, loads and metric window
  as arrays, a power sequence replayed through the runtime plant, and the temperature grid
  of the dynamic programs;
- :mod:`~sma_fmu.analysis.switch_dp`: dynamic programs over that grid for the paper's
  "switch" hysteresis: a rigorous lower bound and an achievable power sequence;
- :mod:`~sma_fmu.analysis.inverse_tracker`: a perfect-knowledge one-step inverse of the
  plant (any mode), an achievable benchmark;
- :mod:`~sma_fmu.analysis.preview_search`: a receding-horizon search over the plant with the
  reference's future known (any mode), a slower, better achievable benchmark;
- :mod:`~sma_fmu.analysis.tracking_bound`: the bound of a scenario, from all of these.

Every model evaluation goes through :mod:`sma_fmu.runtime`; nothing here re-implements
the physics.
"""
