"""The C family of FMUs (issue 25): the runtime in C99 (``runtime/``), the FMI 2.0 layer
(``fmi2/``), the five model adapters (``models/``) and ``sma-fmu build --native``
(:mod:`.native_build`). No Python runs inside these FMUs."""
