"""FMI: the two families of FMUs, building them, driving them from Python, and the C hosts.

Lowest room first; each imports only from rooms before it (``tests/project/test_layout.py``):

- ``c_common/``: C code both families compile (the resource-location URI, log categories,
  the saved-state frame) and ``include/``, the FMI standard's headers (the one declaration of
  the FMI ABI: both families, the hosts and the bench's C FMU compile with it);
- ``python_family/``: the pythonfmu FMUs' code: ``slave_support/`` (the FMI glue every such
  FMU ships) and ``front/`` (the C front, the FMU's binary in front of pythonfmu's);
- ``c_family/``: the C family ("native" FMUs, ``sma-fmu build --native``): ``runtime/`` (the
  physics in C99), ``core/`` (the version-neutral layer), ``fmi2/`` and ``fmi3/`` (the FMI
  fronts) and ``adapter_support/`` (what the model adapters share);
- ``models/``: one folder per FMU (its pythonfmu slave, its C adapter, its documentation page
  and its declaration ``fmu.toml``) and the registry listing them (:mod:`.models`);
- ``hosts/``: small C programs that run FMUs the way non-Python tools do, and their build;
- ``driving/``: running an FMU from Python through fmpy (:mod:`.driving.instance`);
- ``loop/``: the closed loop of the five FMUs, described once (:mod:`.loop.system`): what
  the masters run, the exports write and each FMU's page shows;
- ``packaging/``: building either family (:mod:`.packaging.build`), model descriptions,
  documentation, reference results, the cross-check tree, platform tables.
"""
