"""FMI: the two families of FMUs, building them, driving them from Python, and the C hosts.

Lowest room first; each imports only from rooms before it (``tests/test_layout.py``):

- ``c_common/``: C code both families compile (the resource-location URI, log categories,
  the saved-state frame) and ``include/``, the FMI standard's headers (the one declaration of
  the FMI ABI: both families, the hosts and the bench's C FMU compile with it);
- ``python_family/``: the pythonfmu FMUs' code: ``slaves/`` (one slave script per FMU),
  ``slave_support/`` (the FMI glue every such FMU ships) and ``front/`` (the C front, the
  FMU's binary in front of pythonfmu's);
- ``c_family/``: the C family ("native" FMUs, ``sma-fmu build --native``): ``runtime/`` (the
  physics in C99), ``fmi2/`` (the FMI 2.0 layer) and ``models/`` (the five adapters);
- ``hosts/``: small C programs that run FMUs the way non-Python tools do, and their build;
- ``driving/``: running an FMU from Python through fmpy (:mod:`.driving.instance`);
- ``packaging/``: building either family (:mod:`.packaging.build`), model descriptions,
  documentation, reference results, the cross-check tree, platform tables.
"""
