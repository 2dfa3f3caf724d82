"""``sma-fmu build --native``: the five FMUs as C source-code FMUs with native binaries.

Each native FMU holds:
- ``modelDescription.xml``: the pythonfmu FMU's, made native (:mod:`.native_description`),
  with ``<SourceFiles>`` listing ``sources/``;
- ``sources/``: the C files it needs, flat (the FMI 2.0 layer ``fmi2/``, its adapter
  ``models/<Model>.c``, the runtime modules it includes, transitively, the FMI headers) and
  the generated ``<Model>_variables.h``: what a tool compiles (fmpy's
  ``build_platform_binary`` does, with sources/ as its include folder);
- ``binaries/linux64/<Model>.so`` (gcc) and ``binaries/win64/<Model>.dll`` (mingw-w64;
  without it the build warns and leaves win64 out, as the pythonfmu build does), both built
  with :data:`FLAGS` (``-Werror``; ``-ffp-contract=off``: no fused multiply-add, so results
  stay equal to the Python runtime's on every machine), exporting only the fmi2 functions,
  linking no libpython;
- ``resources/parameters.json``: the wire parameter file of the build, for the record
  (``sma-fmu check``): the binary has its values compiled in and reads only
  ``resources/start_values.json``, which ``sma-fmu export`` packs;
- ``extra/``: the pythonfmu twin's, if it has one (its reference result: the same numbers).
"""
import re
import shutil
import subprocess
import sys
import tempfile
import warnings
import zipfile
from importlib import util
from pathlib import Path

from sma_fmu.files.output_folder import staged_folder
from sma_fmu.files.package_data import shipped_file
from sma_fmu.fmi.hosts import c_compiler, windows_compiler
from sma_fmu.fmi.packaging.c_family_description import native_description, variables_header
from sma_fmu.fmi.packaging.fmu_names import FMU_SCRIPTS
from sma_fmu.fmi.packaging.front_build import FrontWarning
from sma_fmu.fmi.packaging.platforms import NATIVE_MARKER, PlatformEntry, annotate
from sma_fmu.fmi.packaging.pythonfmu_build import build_pythonfmu_fmus
from sma_fmu.fmi.packaging.reproducible import fix_timestamps

__all__ = ["FLAGS", "NATIVE_MARKER", "NativeBuildWarning", "C_FAMILY", "model_sources",
           "build_native_fmus", "compile_binary"]

C_FAMILY = Path(__file__).parents[1] / "c_family"
C_COMMON = Path(__file__).parents[1] / "c_common"   # C code both families compile
FLAGS = ["-std=c99", "-Wall", "-Wextra", "-Wpedantic", "-Werror", "-ffp-contract=off", "-O2",
         "-shared"]
_TARGETS = {"linux64": {"flags": ["-fPIC", "-fvisibility=hidden", "-Wl,--no-undefined"],
                        "libraries": ["-lm"],
                        "suffix": ".so"},
            "win64": {"flags": ["-static-libgcc", "-D__USE_MINGW_ANSI_STDIO=1", "-s",
                                "-Wl,--no-insert-timestamp", "-Wl,--disable-auto-image-base"],
                      "libraries": [], "suffix": ".dll"}}
_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


class NativeBuildWarning(FrontWarning):
    """A native FMU was built without the binary of a platform (no compiler for it)."""


def _c_files():
    """{file name: path} of the C family's shipped files (flat names are unique)."""
    files = {}
    for folder in (C_FAMILY / "fmi2", C_FAMILY / "runtime", C_FAMILY / "models", C_COMMON):
        for path in sorted(folder.iterdir()):
            if path.suffix in (".c", ".h"):
                if path.name in files:
                    raise ValueError(f"C family: {path.name} is in two folders")
                files[path.name] = path
    return files


def _implementers(files):
    """{header: [.c files implementing it]}: a .c file implements the header it includes
    first (runtime/json_repr.c implements part of json_text.h); adapters implement none."""

    found = {}
    for name, path in files.items():
        if name.endswith(".c") and name[:-2] not in FMU_SCRIPTS:
            first = _INCLUDE.search(path.read_text(encoding="utf-8"))
            if first:
                found.setdefault(first.group(1), []).append(name)
    return found


def model_sources(model_name, generated=()):
    """The file names sources/ needs for ``model_name``: its adapter, the layer, and every
    header they include, transitively, with the .c files implementing it; ``generated``
    names files written later."""
    files = _c_files()
    implementers = _implementers(files)
    wanted = [f"{model_name}.c"] + sorted(n for n in files if n.startswith("fmi2") or n == "sma_model.c")
    found, queue = set(), list(wanted)
    while queue:
        name = queue.pop()
        if name in found:
            continue
        found.add(name)
        if name in generated:
            continue
        if name not in files:
            raise ValueError(f"C family: {name} is included but does not exist")
        for header in _INCLUDE.findall(files[name].read_text(encoding="utf-8")):
            queue.append(header)
            queue.extend(implementers.get(header, ()))
    return sorted(found)


def compile_binary(platform, sources_folder, output):
    """Compile the .c files of ``sources_folder`` into ``output`` for ``platform``; returns
    None or the reason it could not (no compiler, or its last error line)."""
    target = _TARGETS[platform]
    compiler = c_compiler() if platform == "linux64" else windows_compiler()
    if platform == "linux64" and not (sys.platform.startswith("linux") and sys.maxsize > 2 ** 32):
        return f"the linux64 binary is built on 64-bit Linux only (this is {sys.platform})"
    if shutil.which(compiler[0]) is None:
        return f"no {'mingw-w64 cross ' if platform == 'win64' else ''}C compiler ({compiler[0]} not found)"
    command = [*compiler, *FLAGS, *target["flags"], "-I", str(sources_folder), "-o", str(output),
               *sorted(str(p) for p in Path(sources_folder).glob("*.c")), *target["libraries"]]
    try:
        result = subprocess.run(command, capture_output=True, text=True, timeout=600)
    except (OSError, subprocess.SubprocessError) as error:
        return f"C compiler {' '.join(compiler)!r} could not run ({error})"
    if result.returncode != 0 or not Path(output).is_file():
        message = result.stderr.strip() or "no message"
        raise RuntimeError(f"C compiler {' '.join(compiler)!r} failed (a bug of the C family, "
                           f"not of the machine): {message[-3000:]}")
    return None


def _exact_starts(model_name, resources_folder):
    """{name: value} of every variable of the Python slave as it starts (exact floats)."""

    path = shipped_file("slaves", FMU_SCRIPTS[model_name])
    spec = util.spec_from_file_location(f"_sma_native_{model_name}", path)
    module = util.module_from_spec(spec)
    spec.loader.exec_module(module)
    slave = getattr(module, model_name)(instance_name="describe", resources=str(resources_folder))
    starts = {v.name: getattr(slave, v.name) for v in slave.vars.values()}
    defaults = slave.interface.defaults if slave.interface.exposed else None
    return starts, defaults


def _build_one(model_name, python_fmu, folder, work):
    """Write ``folder/<model_name>.fmu`` from the pythonfmu FMU; returns [warning texts]."""
    unpacked = work / model_name
    with zipfile.ZipFile(python_fmu) as archive:
        archive.extractall(unpacked)
    starts, defaults = _exact_starts(model_name, unpacked / "resources")
    header_name = f"{model_name}_variables.h"
    names = model_sources(model_name, generated=(header_name,))
    python_description = (unpacked / "modelDescription.xml").read_bytes()
    description, _ = native_description(python_description, starts,
                                        [name for name in names if name.endswith(".c")])
    sources = work / f"{model_name}.sources"
    sources.mkdir()
    files = _c_files()
    for name in names:
        if name != header_name:
            shutil.copyfile(files[name], sources / name)
    (sources / header_name).write_text(variables_header(description, starts, defaults),
                                       encoding="utf-8")
    binaries, problems, entries = {}, [], []
    for platform, target in _TARGETS.items():
        output = work / f"{model_name}{target['suffix']}"
        problem = compile_binary(platform, sources, output)
        if problem:
            problems.append(f"{model_name}: built without {platform}: {problem}")
            continue
        binary = f"binaries/{platform}/{model_name}{target['suffix']}"
        binaries[binary] = output.read_bytes()
        if NATIVE_MARKER not in binaries[binary]:
            raise RuntimeError(f"{binary}: the native marker is missing (fmi2_functions.c)")
        entries.append(PlatformEntry(platform, binary, front=False, python="none (native C)",
                                     native=True))
    text = annotate(description.decode("utf-8"), entries)
    fmu = folder / f"{model_name}.fmu"
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("modelDescription.xml", text)
        for name in names:
            archive.write(sources / name, f"sources/{name}")
        for binary, data in binaries.items():
            archive.writestr(binary, data)
        archive.write(unpacked / "resources" / "parameters.json", "resources/parameters.json")
        for extra in sorted((unpacked / "extra").rglob("*")) if (unpacked / "extra").is_dir() else ():
            if extra.is_file():  # the twin's reference result (fmi-ls-ref): the same numbers
                archive.write(extra, extra.relative_to(unpacked).as_posix())
    fix_timestamps(fmu)  # reproducible.py: the same inputs, the same bytes
    return problems


def build_native_fmus(out_dir, parameter_file=None, names=None):
    """Build the native FMUs (default: all five) into ``out_dir``; return {name: path}.

    Built beside ``out_dir`` and moved there at the end: a failed build leaves it as it was.
    """

    names = list(FMU_SCRIPTS) if names is None else list(names)
    with tempfile.TemporaryDirectory(prefix="sma_fmu_native_") as work:
        work = Path(work)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FrontWarning)  # the twins' fronts: not shipped
            python_fmus = build_pythonfmu_fmus(work / "python", parameter_file, names)
        problems = []
        with staged_folder(out_dir) as folder:
            for name in names:
                problems += _build_one(name, python_fmus[name], folder, work)
    for message in sorted(set(p.split(": ", 1)[1] for p in problems)):
        hint = (" Install mingw-w64 (Debian: apt-get install gcc-mingw-w64-x86-64) or set "
                "SMA_FMU_WIN64_CC" if message.startswith("built without win64") else
                " Their sources/ compile there: fmpy.build.build_platform_binary")
        warnings.warn(NativeBuildWarning(f"native FMUs {message}.{hint}"), stacklevel=2)
    return {name: Path(out_dir) / f"{name}.fmu" for name in names}
