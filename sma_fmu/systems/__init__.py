"""The closed loop in system-level tools: SSP packages, a container FMU, hosts, compliance checks.

- :mod:`.closed_loop`: a scenario's loop system (:mod:`sma_fmu.fmi.loop`) with the FMUs
  built in a folder, and identifiers as hosts need them;
- :mod:`.ssp`: the SSP 1.0 package (SystemStructure.ssd + the FMUs);
- :mod:`.packed`: the FMUs packed with the scenario's values as their defaults;
- :mod:`.container`: the whole loop as one FMI 2.0 FMU (fmu-manipulation-toolbox);
- :mod:`.hosts`: running them in libcosim, Ecos and fmpy, results as loop time series
  (:mod:`.libcosim_flags`: libcosim's Booleans, logged alone);
  :mod:`.omsimulator` and :mod:`.fmpy_ssp`: the SSP in OMSimulator and fmpy's ``simulate_ssp``;
- :mod:`.host_needs`: what each known SSP host needs and applies;
- :mod:`.loop_host`: the loop in the plain C loop host; :mod:`.c_master` (with
  :mod:`.c_master_rows` and :mod:`.loop_host_process`): that host as the C master of
  ``sma-fmu run --master c``, one process for many runs;
- :mod:`.check`: the compliance check behind ``sma-fmu check``.
"""
