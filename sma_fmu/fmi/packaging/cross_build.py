"""The platforms the C family is built for, and the compilers that build them.

One table, :data:`TARGETS`, keyed by the FMI 3.0 platform tuple (``x86_64-linux``...), gives
each target its FMI 2.0 folder name where FMI 2.0 defines one (``linux64``, ``win64``,
``darwin64``, ``win32``; FMI 2.0 has no name for aarch64), the binary's suffix, the
toolchains that build it, best first, and how the tests run it on this project's CI
machine (x86-64 Linux): ``native``, ``wine``, ``qemu`` or ``None`` (only built).

Toolchains: the system gcc for x86_64-linux (the binary whose speed ``sma-fmu bench``
measures), mingw-w64 for the Windows targets, and ``zig cc`` (PyPI ``ziglang``, run as
``python -m ziglang cc``: clang with every target's libc) for all of them, the only one for
aarch64-linux and macOS. :func:`compile_shared` compiles a folder of C files with
:data:`FLAGS` (``-Werror``; ``-ffp-contract=off``: no fused multiply-add) for one target.
"""
import hashlib
import importlib.util
import os
import platform
import shlex
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

from sma_fmu.fmi.c_common import include_flags
from sma_fmu.console.interrupts import run_child
from sma_fmu.fmi.hosts import HOSTS, c_compiler, windows_compiler

__all__ = ["FLAGS", "Target", "TARGETS", "target", "fmi2_targets", "zig_command", "toolchain",
           "compile_shared", "compile_host_for", "RUNS_HERE"]

FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-ffp-contract=off", "-O2",
         "-shared"]
RUNS_HERE = {"native": "run natively (x86-64 Linux)", "wine": "run under wine64",
             "qemu": "run under qemu-aarch64 (qemu-user)", None: "only built, never run"}


@dataclass(frozen=True)
class Target:
    """One platform of the C family."""

    tuple: str                 # FMI 3.0 platform tuple
    fmi2: str | None           # FMI 2.0 binaries/ folder, None where FMI 2.0 names none
    zig: str                   # zig cc -target
    suffix: str
    flags: tuple = ()
    libraries: tuple = ()
    gcc: str | None = None     # "host" (the system compiler), "mingw64", or None
    runs: str | None = None    # how the tests run it here: a key of RUNS_HERE

    def folder(self, fmi_version=2):
        """The binaries/ folder name under FMI ``fmi_version`` (None: no name there)."""
        return self.fmi2 if fmi_version == 2 else self.tuple


_ELF = ("-fPIC", "-fvisibility=hidden")
_WINDOWS = ("-D__USE_MINGW_ANSI_STDIO=1", "-s")
_MINGW = ["-static-libgcc", "-Wl,--no-insert-timestamp",  # no PE date,
          "-Wl,--disable-auto-image-base"]                 # nor an image base from the path
TARGETS = {t.tuple: t for t in (
    Target("x86_64-linux", "linux64", "x86_64-linux-gnu.2.17", ".so", _ELF + ("-Wl,--no-undefined",),
           ("-lm",), gcc="host", runs="native"),
    Target("x86_64-windows", "win64", "x86_64-windows-gnu", ".dll", _WINDOWS, gcc="mingw64",
           runs="wine"),
    Target("x86_64-darwin", "darwin64", "x86_64-macos", ".dylib", ("-fPIC", "-fvisibility=hidden")),
    Target("x86-windows", "win32", "x86-windows-gnu", ".dll", _WINDOWS),
    Target("aarch64-linux", None, "aarch64-linux-gnu.2.17", ".so", _ELF + ("-Wl,--no-undefined",),
           ("-lm",), runs="qemu"),
    Target("aarch64-darwin", None, "aarch64-macos", ".dylib", ("-fPIC", "-fvisibility=hidden")),
)}


def target(name):
    """The :class:`Target` of an FMI 3.0 tuple or an FMI 2.0 folder name."""
    for entry in TARGETS.values():
        if name in (entry.tuple, entry.fmi2):
            return entry
    raise KeyError(f"no C-family target {name!r}; known: "
                   f"{', '.join(n for t in TARGETS.values() for n in (t.tuple, t.fmi2) if n)}")


def fmi2_targets():
    """The targets FMI 2.0 has a folder name for, in table order."""
    return [t for t in TARGETS.values() if t.fmi2]


def zig_command():
    """zig cc as a command list: ``$SMA_FMU_ZIG_CC`` split like a shell would (``none``: no
    zig), else ``python -m ziglang cc`` when PyPI's ``ziglang`` is installed in this Python,
    else ``zig cc`` on the PATH, else the zig of the ``ziglang`` package whose script
    ``python-zig`` is on the PATH (e.g. of an activated venv: what an isolated wheel build
    finds), else None."""
    given = os.environ.get("SMA_FMU_ZIG_CC", "").strip()
    if given:
        return None if given.lower() == "none" else shlex.split(given)
    if importlib.util.find_spec("ziglang") is not None:
        return [sys.executable, "-m", "ziglang", "cc"]
    if shutil.which("zig"):
        return ["zig", "cc"]
    script = shutil.which("python-zig")
    return None if script is None else _ziglang_binary(script)


def _ziglang_binary(script):
    """[zig, "cc"] of the ``ziglang`` package whose script ``python-zig`` is ``script``: its
    own Python (the script's first line) names the package's folder. That Python is asked
    without the calling process's PYTHONPATH, which an isolated wheel build points at its own
    packages only, so that the script itself, run there, cannot import ziglang."""
    with open(script, "rb") as handle:
        first = handle.readline().decode("utf-8", "replace").strip()
    interpreter = shlex.split(first[2:]) if first.startswith("#!") else [sys.executable]
    clean = {key: value for key, value in os.environ.items()
             if key not in ("PYTHONPATH", "PYTHONNOUSERSITE", "PYTHONHOME")}
    try:
        found = subprocess.run([*interpreter, "-c", "import ziglang, os; print(os.path.dirname(ziglang.__file__))"],
                               capture_output=True, text=True, env=clean, timeout=60)
    except (OSError, subprocess.TimeoutExpired):
        return None
    zig = Path(found.stdout.strip()) / ("zig.exe" if os.name == "nt" else "zig")
    return [str(zig), "cc"] if found.returncode == 0 and zig.is_file() else None


def _x86_64_linux():
    return sys.platform.startswith("linux") and platform.machine().lower() in ("x86_64", "amd64")


def toolchain(entry, prefer_zig=False):
    """(compiler command, its extra flags) for ``entry``, or (None, reason) when none is here."""
    if not prefer_zig and entry.gcc == "host" and _x86_64_linux() and shutil.which(c_compiler()[0]):
        return c_compiler(), []
    if not prefer_zig and entry.gcc == "mingw64" and shutil.which(windows_compiler()[0]):
        return windows_compiler(), _MINGW
    zig = zig_command()
    if zig is None:
        other = {"host": "gcc on x86-64 Linux, ", "mingw64": "mingw-w64, "}.get(entry.gcc, "")
        return None, f"no compiler for {entry.tuple} ({other}or zig: pip install ziglang)"
    return [*zig, "-target", entry.zig], ["-s"]


def _cache_file(command, sources_folder, output):
    """Where the output of ``command`` over ``sources_folder``'s files is kept (a compiler's
    output is a function of its command and its inputs, as for ccache)."""
    digest = hashlib.sha256("\0".join(command).encode())
    for path in sorted(Path(sources_folder).iterdir()):
        digest.update(path.name.encode() + b"\0" + path.read_bytes())
    return Path(tempfile.gettempdir()) / "sma-fmu-c-family" / digest.hexdigest()[:24] / Path(output).name


def compile_shared(entry, sources_folder, output, prefer_zig=False):
    """Compile the .c files of ``sources_folder`` into the shared library ``output`` for
    ``entry``; returns None, or the reason no compiler for it is here. A compiler that
    fails raises RuntimeError with its message: the sources are at fault, not the machine.

    It runs on a copy of the sources, on relative names, writing the output's own name (a
    DLL's export table and a dylib's install name hold it): no build path gets into the
    binary. The result is kept in a cache under the temporary folder, keyed by the command
    and the sources (as ccache does)."""
    compiler, extra = toolchain(entry, prefer_zig)
    if compiler is None:
        return extra
    name = Path(output).name
    command = [*compiler, *FLAGS, *entry.flags, *extra, "-I", ".", "-o", name,
               *sorted(p.name for p in Path(sources_folder).glob("*.c")), *entry.libraries]
    cached = _cache_file(command, sources_folder, output)
    if not cached.is_file():
        cached.parent.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryDirectory(dir=cached.parent) as stage:
            for path in Path(sources_folder).iterdir():
                if path.suffix in (".c", ".h"):
                    shutil.copyfile(path, Path(stage) / path.name)
            try:
                result = run_child(command, text=True, timeout=900, cwd=stage, own_temp=True)
            except (OSError, subprocess.SubprocessError) as error:
                return f"C compiler {' '.join(compiler)!r} could not run ({error})"
            if result.returncode != 0 or not (Path(stage) / name).is_file():
                message = result.stderr.strip() or "no message"
                raise RuntimeError(f"C compiler {' '.join(compiler)!r} failed for {entry.tuple} "
                                   f"(a bug of the C family, not of the machine): {message[-3000:]}")
            os.replace(Path(stage) / name, cached)  # atomic: a parallel build sees all or nothing
    shutil.copyfile(cached, output)
    return None


def compile_host_for(entry, name, output):
    """Cross-build the dlopen C host ``name`` (fmi_host or loop_host, sma_fmu/fmi/hosts/) for
    the Linux target ``entry`` with zig into ``output``; it loads ``binaries/<tuple>/``.
    Returns None or the reason it could not (no zig)."""
    zig = zig_command()
    if zig is None:
        return "no zig cc (pip install ziglang)"
    if not entry.tuple.endswith("-linux"):
        raise ValueError(f"C hosts are cross-built for Linux targets only, not {entry.tuple}")
    output = Path(output)
    output.parent.mkdir(parents=True, exist_ok=True)
    command = [*zig, "-target", entry.zig, "-std=c11", "-O2", "-Wall", "-Wextra", "-Werror",
               f'-DPLATFORM="{entry.tuple}"', *include_flags(HOSTS), "-o", str(output),
               str(HOSTS / f"{name}.c"), "-ldl"]
    result = run_child(command, text=True, timeout=900, own_temp=True)
    if result.returncode != 0:
        raise RuntimeError(f"zig cc could not build {name} for {entry.tuple}: {result.stderr[-3000:]}")
    return None
