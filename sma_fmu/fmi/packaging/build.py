"""``sma-fmu build``: either family's FMUs, and fmpy's validation of any FMU.

- the Python family (pythonfmu, behind the C front): :mod:`.pythonfmu_build`;
- the C family (``--native``: no Python inside): :mod:`.c_family_build` (FMI 2.0) and
  :mod:`.fmi3_build` (``--fmi 3``: FMI 3.0 co-simulation; the pythonfmu family is FMI 2.0
  only).
"""
from pathlib import Path

from sma_fmu.fmi.driving.description import read_description
from sma_fmu.fmi.packaging.c_family_build import build_native_fmus
from sma_fmu.fmi.packaging.fmi3_build import build_fmi3_fmus
from sma_fmu.fmi.packaging.fmu_names import DEFAULT_FMU_DIR
from sma_fmu.fmi.packaging.pythonfmu_build import build_pythonfmu_fmus

__all__ = ["build_fmus", "build_fmu", "validate_fmus"]


def build_fmus(out_dir=DEFAULT_FMU_DIR, parameter_file=None, names=None, native=False,
               fmi_version=2, compile=False):
    """Build FMUs (default: every registered one, :mod:`sma_fmu.fmi.models`) into ``out_dir``;
    return {name: path}.

    They are built in a temporary folder beside ``out_dir`` and moved there at the end, so
    a failed build leaves ``out_dir`` as it was. ``native``: the C family instead
    (:mod:`sma_fmu.fmi.packaging.c_family_build`: same interface, no Python inside), whose
    binaries are the wheel's prebuilt ones unless ``compile`` (or none fits).
    ``fmi_version`` 3: the C family as FMI 3.0 co-simulation FMUs (needs ``native``).
    """
    if fmi_version not in (2, 3):
        raise ValueError(f"FMI version {fmi_version!r}: 2 or 3")
    if fmi_version == 3 and not native:
        raise ValueError("FMI 3.0 FMUs are built by the C family only (--native): pythonfmu is "
                         "FMI 2.0 only")
    if fmi_version == 3:
        return build_fmi3_fmus(out_dir, parameter_file, names, compile)
    if native:
        return build_native_fmus(out_dir, parameter_file, names, compile)
    return build_pythonfmu_fmus(out_dir, parameter_file, names)

def build_fmu(model_name, out_dir=DEFAULT_FMU_DIR, parameter_file=None):
    """Build one FMU (a registered name, :mod:`sma_fmu.fmi.models`) into ``out_dir``; return its path."""
    return build_fmus(out_dir, parameter_file, [model_name])[model_name]


def validate_fmus(paths):
    """fmpy's validation of each FMU: {path: list of problems} (empty list = valid).

    A file that is not an FMU at all (missing, a folder, not a zip archive, no model
    description) raises :class:`FmuFileError` before anything is validated.
    """
    from fmpy.validation import validate_fmu

    paths = [Path(path) for path in paths]
    for path in paths:
        read_description(path)
    return {path: validate_fmu(str(path)) for path in paths}
