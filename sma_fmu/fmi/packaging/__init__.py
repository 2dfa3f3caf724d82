"""Building the FMUs of either family and what they carry.

- :mod:`.build`: ``sma-fmu build`` (either family) and fmpy's validation;
- :mod:`.pythonfmu_build`, :mod:`.front_build`: the Python family and its C front;
- :mod:`.c_family_build`, :mod:`.c_family_description`: the C family (``--native``);
  :mod:`.parameter_table`: its wire parameter table, generated from the Python schema;
- :mod:`.fmu_names`: the FMUs by name (the registry's, :mod:`sma_fmu.fmi.models`) and their
  default folder;
- :mod:`.documentation`, :mod:`.reference_results`, :mod:`.extras`: ``documentation/`` and
  the fmi-ls-ref reference results every FMU carries; :mod:`.user_guide`: each model's page
  (``fmi/models/<Model>/page.html``) in it (the loop's wiring is :mod:`sma_fmu.fmi.loop.wiring`'s);
- :mod:`.cross_check`: the FMI Cross-Check tree; :mod:`.platforms`: the platform tables;
  :mod:`.variable_table`: the variable tables of docs/fmus.md.
"""
