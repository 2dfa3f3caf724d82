"""The project's build backend: setuptools' (``setuptools.build_meta``), with the prebuilt
binaries compiled into the wheel.

``python -m build`` (or ``pip wheel .``) runs ``python -m sma_fmu.fmi.packaging.prebuilt_writer``
before setuptools builds the wheel, so the wheel carries the C family's binaries (FMI 2.0 and
3.0), the Python family's fronts and the C hosts (``sma_fmu/fmi/packaging/prebuilt_binaries/``,
``sma_fmu/fmi/hosts/prebuilt/``): with them ``sma-fmu build [--native [--fmi 3]]`` and
``sma-fmu check`` need no compiler. The writer needs gcc, mingw-w64 and zig (``$SMA_FMU_ZIG_CC``, or ``zig`` or
ziglang's ``python-zig`` on the PATH: an isolated build does not see a venv's ``ziglang``
module, but it sees that venv's ``bin/`` when the venv is activated). Where one is missing the
wheel is built without them, and the build says so: ``sma-fmu build --native`` then compiles
where it runs, as a wheel built from source always did.

``SMA_FMU_PREBUILT`` chooses: ``auto`` (the default: the binaries where the compilers are),
``require`` (a missing compiler fails the build: a wheel to publish) or ``skip``.

Only the wheel gets them. The sdist holds none (MANIFEST.in prunes them) and an editable
install compiles nothing; that is why this is a backend wrapping setuptools' and not a
setuptools command: a ``build_py`` step also runs for ``pip install -e .`` (minutes of
compiling into the checkout) and cannot add build requirements, while
:func:`get_requires_for_build_wheel` installs the packages the writer imports into the
isolated build environment only when the writer will run. The folders the writer fills are
generated, never committed (.gitignore): the build leaves the checkout as it found it.
"""
import contextlib
import importlib.util
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import tomllib
from pathlib import Path

from setuptools import build_meta as _setuptools
from setuptools.build_meta import *  # noqa: F401,F403 - every other hook is setuptools' own

ROOT = Path(__file__).resolve().parent.parent
MODE_VARIABLE = "SMA_FMU_PREBUILT"
MODES = ("auto", "require", "skip")
# what the writer imports beyond the standard library (it builds the FMUs: their descriptions,
# reference results and pages; cosim_host links libcosimpy's libcosimc); their version
# constraints are the project's dependencies'
WRITER_IMPORTS = ("numpy", "matplotlib", "fmpy", "pythonfmu", "libcosimpy")


def _mode():
    mode = os.environ.get(MODE_VARIABLE, "").strip().lower() or "auto"
    if mode not in MODES:
        raise ValueError(f"{MODE_VARIABLE}={os.environ[MODE_VARIABLE]!r}: must be one of {', '.join(MODES)}")
    return mode


def _sma_fmu():
    """Make the checkout's sma_fmu importable here (its build modules need only the standard library)."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))


def _targets():
    """The C family's targets the writer compiles (prebuilt_writer.write_prebuilt): every
    target of the cross-build table, FMI 3.0's, of which FMI 2.0 names four."""
    from sma_fmu.fmi.packaging.cross_build import TARGETS
    return list(TARGETS.values())


def missing_compilers():
    """One text per compiler the writer needs and this machine lacks (empty: all there)."""
    _sma_fmu()
    from sma_fmu.fmi.hosts import c_compiler, windows_compiler
    from sma_fmu.fmi.packaging.cross_build import toolchain

    reasons = []
    for what, command in (("the C compiler (gcc, or $CC)", c_compiler()),   # the linux64 front, the hosts
                          ("mingw-w64 ($SMA_FMU_WIN64_CC)", windows_compiler())):  # the win64 front
        if shutil.which(command[0]) is None:
            reasons.append(f"{what}: {command[0]} is not on the PATH")
    for entry in _targets():
        compiler, reason = toolchain(entry)
        if compiler is None:
            reasons.append(reason)
        elif shutil.which(compiler[0]) is None:
            reasons.append(f"no compiler for {entry.tuple}: {compiler[0]} is not on the PATH")
    return list(dict.fromkeys(reasons))


def _requirement_name(requirement):
    return re.split(r"[\s\[<>=!~;@]", requirement, maxsplit=1)[0].lower()


def writer_requirements():
    """The project's dependencies the writer imports (WRITER_IMPORTS), as pyproject.toml states
    them: in its dependencies or one of its extras (libcosimpy is the systems extra's)."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))["project"]
    extras = project.get("optional-dependencies", {})
    dependencies = project["dependencies"] + [r for name, listed in extras.items()
                                              if name not in ("all", "test") for r in listed]
    chosen = list({_requirement_name(r): r for r in reversed(dependencies)
                   if _requirement_name(r) in WRITER_IMPORTS}.values())[::-1]
    unknown = set(WRITER_IMPORTS) - {_requirement_name(r) for r in chosen}
    if unknown:
        raise RuntimeError(f"wheel_backend.WRITER_IMPORTS names {', '.join(sorted(unknown))}, "
                           "which pyproject.toml's dependencies do not")
    return chosen


def get_requires_for_build_wheel(config_settings=None):
    """setuptools' requirements, and the writer's imports when the writer will run here."""
    requires = _setuptools.get_requires_for_build_wheel(config_settings)
    if _mode() != "skip" and not missing_compilers():
        requires += writer_requirements()
    return requires


def _say(text):
    print(f"sma-fmu wheel: {text}", file=sys.stderr, flush=True)


def _prebuilt_folders():
    _sma_fmu()
    from sma_fmu.fmi.hosts import PREBUILT_HOSTS
    from sma_fmu.fmi.packaging.prebuilt import PREBUILT
    return [PREBUILT, PREBUILT_HOSTS]


def _write_prebuilt():
    """Run the writer if it can run here, else say why not (or fail, under ``require``)."""
    mode = _mode()
    if mode == "skip":
        _say(f"no prebuilt binaries ({MODE_VARIABLE}=skip): "
             "sma-fmu build --native compiles them where it runs")
        return
    reasons = missing_compilers()
    absent = [name for name in WRITER_IMPORTS if importlib.util.find_spec(name) is None]
    if absent and not reasons:  # a build without isolation, in an environment without them
        reasons.append(f"the build environment lacks {', '.join(absent)} (the writer imports them)")
    if reasons:
        text = (f"no prebuilt binaries in this wheel: {'; '.join(reasons)}. sma-fmu build --native "
                "compiles them where it runs (a C compiler there; mingw-w64 and zig for the other "
                "platforms). For a wheel with them: gcc, mingw-w64 and zig (zig or ziglang's "
                "python-zig on the PATH, or SMA_FMU_ZIG_CC)")
        if mode == "require":
            raise RuntimeError(f"{text} ({MODE_VARIABLE}=require)")
        _say(f"{text}; {MODE_VARIABLE}=require makes this an error")
        return
    platforms = ", ".join(entry.tuple for entry in _targets())
    _say(f"compiling the prebuilt binaries (FMI 2.0 and 3.0: {platforms}; the fronts; the C hosts): "
         "a few minutes")
    started = time.monotonic()
    result = subprocess.run([sys.executable, "-m", "sma_fmu.fmi.packaging.prebuilt_writer"], cwd=ROOT)
    if result.returncode != 0:
        raise RuntimeError(f"the prebuilt binaries could not be compiled (the writer's message is above); "
                           f"{MODE_VARIABLE}=skip builds the wheel without them")
    _say(f"prebuilt binaries compiled in {time.monotonic() - started:.0f} s")


@contextlib.contextmanager
def _prebuilt_binaries():
    """The prebuilt folders filled by the writer (or absent) while the wheel is built; after
    it, the checkout as it was (a folder there before, e.g. of a writer run by hand, is put
    back). setuptools' own copies under build/ are removed before and after: its build
    folder keeps files of an earlier build, which would go into this wheel."""
    folders = _prebuilt_folders()
    copies = [ROOT / "build" / "lib" / folder.relative_to(ROOT) for folder in folders]
    with tempfile.TemporaryDirectory(prefix="sma_fmu_prebuilt_kept_") as kept:
        moved = []
        for index, folder in enumerate(folders):
            if folder.exists():
                shutil.move(folder, Path(kept) / str(index))
                moved.append((Path(kept) / str(index), folder))
        try:
            for copy in copies:
                shutil.rmtree(copy, ignore_errors=True)
            _write_prebuilt()
            yield
        finally:
            for folder in folders + copies:
                shutil.rmtree(folder, ignore_errors=True)
            for stash, folder in moved:
                shutil.move(stash, folder)


def build_wheel(wheel_directory, config_settings=None, metadata_directory=None):
    """setuptools' wheel, with the prebuilt binaries where the compilers are (see the module)."""
    with _prebuilt_binaries():
        return _setuptools.build_wheel(wheel_directory, config_settings, metadata_directory)
