"""The closed loop of the five FMUs, described once: every master, system tool and FMU page reads it.

- :mod:`.wiring`: the components, their connections, the Gauss-Seidel step order and the
  outputs the time series records;
- :mod:`.gains`: the controller's gains, by their names in a scenario file, in the
  parameter file and in the loop;
- :mod:`.values`: what a scenario sets in each component (parameter values, input starts);
- :mod:`.wire_values`: the scenario's whole wire in the FMUs that model it, or a refusal
  naming both wires' digests (never a mix);
- :mod:`.system`: one scenario's loop with its FMU files (:func:`.system.loop_system`), the
  check that the FMUs are built and that their variables fit the loop.
"""
