"""The closed loop of the five FMUs, described once: every master, system tool and FMU page reads it.

- :mod:`.gains`: the controller's gains, by their names in a scenario file, in the
  parameter file and in the loop.
"""
