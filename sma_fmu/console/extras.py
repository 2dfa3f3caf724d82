"""The optional dependencies, grouped as pyproject.toml's extras, and the one-line error
naming the extra to install when a command needs one that is missing.

The main job (build the FMUs, run scenarios through them, the model commands) needs none;
each extra below unlocks the commands named beside it. ``pip install "sma-fmu[all]"``
installs every one. tests/project/test_extras.py checks this table against pyproject.toml.
"""
import importlib.util
import sys

__all__ = ["EXTRAS", "MissingExtra", "missing", "require", "extra_of_module"]

# extra -> ((import name, distribution), ...): what the commands of that extra import
EXTRAS = {
    # fit, predict, synth isobaric: least squares, sparse solvers, BLAS threads, workbooks
    "fit": (("scipy", "scipy"), ("threadpoolctl", "threadpoolctl"), ("openpyxl", "openpyxl")),
    # sweep, tune and the studies API: tables, Parquet results, Dask, optimisers
    "studies": (("scipy", "scipy"), ("pandas", "pandas"), ("pyarrow", "pyarrow"),
                ("dask", "dask"), ("distributed", "distributed")),
    # run --format parquet (and reading it back)
    "parquet": (("pyarrow", "pyarrow"),),
    # run --path ssp|container, export container, check: the container builder and FMI
    # checker, and libcosim (wheels for Linux x86_64 only)
    "systems": (("fmu_manipulation_toolbox", "fmu-manipulation-toolbox"),
                ("libcosimpy", "libcosimpy")),
}
_PLATFORM_ONLY = {"libcosimpy": lambda: sys.platform.startswith("linux")
                  and __import__("platform").machine().lower() in ("x86_64", "amd64")}


class MissingExtra(ValueError):
    """A command needs an optional dependency that is not installed; the message names the
    extra that brings it."""


def missing(extra):
    """The distributions of ``extra`` (a key of :data:`EXTRAS`) not installed here (those
    with no wheel for this platform are not asked for)."""
    return [distribution for module, distribution in EXTRAS[extra]
            if _PLATFORM_ONLY.get(module, lambda: True)()
            and importlib.util.find_spec(module) is None]


def require(extra, what):
    """Raise :class:`MissingExtra` (``what needs scipy: pip install "sma-fmu[fit]"``) when a
    dependency of ``extra`` is missing; ``what`` names the command or option."""
    absent = missing(extra)
    if absent:
        raise MissingExtra(f'{what} needs {", ".join(absent)}: pip install "sma-fmu[{extra}]"')


def extra_of_module(name):
    """The smallest extra bringing the top-level module ``name``, or None."""
    found = [extra for extra, modules in EXTRAS.items() if any(m == name for m, _ in modules)]
    return min(found, key=lambda extra: len(EXTRAS[extra])) if found else None
