"""``sma-fmu build --native``: the five FMUs as C source-code FMUs with native binaries.

Each native FMU holds:
- ``modelDescription.xml``: the pythonfmu FMU's, made native (:mod:`.native_description`),
  with ``<SourceFiles>`` listing ``sources/``;
- ``sources/``: the C files it needs, flat (:func:`c_source_files`: the FMI 2.0 layer
  ``fmi2/``, the core, its adapter ``<Model>.c`` from its folder ``fmi/models/<Model>/``, the
  runtime modules it includes, transitively, the standard's FMI headers from
  ``fmi/c_common/include/``) and the generated ``<Model>_variables.h`` and
  ``sma_parameters_table.h`` (the wire parameter schema, :mod:`.parameter_table`): what a tool compiles
  (fmpy's ``build_platform_binary`` does, with sources/ as its include folder);
- a binary for each FMI 2.0 platform of :mod:`.cross_build`'s table:
  ``binaries/linux64/<Model>.so`` (gcc), ``binaries/win64/<Model>.dll`` (mingw-w64),
  ``binaries/darwin64/<Model>.dylib`` and ``binaries/win32/<Model>.dll`` (zig cc); zig cc is
  the fallback of the others; a platform with no compiler here is left out with a warning. All are built with :data:`FLAGS`
  (``-Werror``; ``-ffp-contract=off``: no fused multiply-add, so results stay equal to the
  Python runtime's on every machine), export only the fmi2 functions and link no libpython;
- ``resources/parameters.json``: the wire parameter file of the build, for the record
  (``sma-fmu check``), and ``resources/model_starts.json``: the start of every variable
  (:func:`exact_starts`, the pythonfmu slave's) and the wire parameter file's values, which
  the binary reads (it holds none of them: one binary serves every parameter file), then
  ``resources/start_values.json``, which ``sma-fmu export`` packs;
- ``extra/``: the pythonfmu twin's, if it has one (its reference result: the same numbers).
- ``documentation/``: index.html and result.png (:func:`.extras.add_documentation`) for
  this FMU, its figure from that reference result.
"""
import re
import shutil
import tempfile
import warnings
import zipfile
from importlib import util
from pathlib import Path

from sma_fmu.console import progress
from sma_fmu.files.output_folder import staged_folder
from sma_fmu.fmi.c_common import C_COMMON, FMI_HEADERS
from sma_fmu.fmi.models import declaration, declarations
from sma_fmu.fmi.packaging.cross_build import FLAGS, RUNS_HERE, compile_shared, fmi2_targets, target
from sma_fmu.fmi.packaging.c_family_description import model_starts, native_description, variables_header
from sma_fmu.fmi.packaging.extras import add_documentation
from sma_fmu.fmi.packaging.parameter_table import generated_folder
from sma_fmu.fmi.packaging.front_build import FrontWarning
from sma_fmu.fmi.packaging.platforms import NATIVE_MARKER, PlatformEntry, annotate
from sma_fmu.fmi.packaging.prebuilt import find_prebuilt, sources_digest
from sma_fmu.fmi.packaging.pythonfmu_build import build_pythonfmu_fmus
from sma_fmu.fmi.packaging.reference_results import MANIFEST
from sma_fmu.fmi.packaging.reproducible import fix_timestamps

__all__ = ["FLAGS", "NATIVE_MARKER", "NativeBuildWarning", "C_FAMILY", "c_source_folders",
           "c_source_files", "model_sources", "exact_starts", "build_from_twins",
           "build_native_fmus", "compile_binary"]

C_FAMILY = Path(__file__).parents[1] / "c_family"
_INCLUDE = re.compile(r'^\s*#\s*include\s+"([^"]+)"', re.M)


class NativeBuildWarning(FrontWarning):
    """A native FMU was built without the binary of a platform (no compiler for it)."""


def c_source_folders():
    """The folders of the C files a C-family FMU is compiled from: the two FMI fronts, the
    core, the runtime, the adapters' shared helpers, the C code both families share, the
    standard's FMI headers, the tables generated from the Python schema
    (:mod:`.parameter_table`), and each registered FMU's folder (its adapter ``<Model>.c``)."""
    return [C_FAMILY / "fmi2", C_FAMILY / "fmi3", C_FAMILY / "core", C_FAMILY / "runtime",
            C_FAMILY / "adapter_support", C_COMMON, FMI_HEADERS, generated_folder(),
            *(declared.folder for declared in declarations())]


def c_source_files():
    """{file name: path} of the .c and .h files of :func:`c_source_folders`: the names are
    unique, as a flat ``sources/`` needs (ValueError naming a file in two folders)."""
    files = {}
    for folder in c_source_folders():
        for path in sorted(folder.iterdir()):
            if path.suffix in (".c", ".h"):
                if path.name in files:
                    raise ValueError(f"C family: {path.name} is in two folders")
                files[path.name] = path
    return files


def _implementers(files):
    """{header: [.c files implementing it]}: a .c file implements the header it includes
    first (runtime/json_repr.c implements part of json_text.h); adapters implement none."""

    adapters = {declared.c_model.name for declared in declarations()}
    found = {}
    for name, path in files.items():
        if name.endswith(".c") and name not in adapters:
            first = _INCLUDE.search(path.read_text(encoding="utf-8"))
            if first:
                found.setdefault(first.group(1), []).append(name)
    return found


def model_sources(model_name, generated=(), front="fmi2"):
    """The file names sources/ needs for ``model_name``: its adapter, the FMI ``front``
    (``fmi2`` or ``fmi3``), the core, and every header they include, transitively, with the
    .c files implementing it; ``generated`` names files written later."""
    files = c_source_files()
    implementers = _implementers(files)
    wanted = [f"{model_name}.c"] + sorted(n for n in files if n.startswith(front) or
                                          n.startswith("layer") or n == "sma_model.c")
    other = {"fmi2": "fmi3", "fmi3": "fmi2"}[front]  # the other front is never compiled in
    found, queue = set(), list(wanted)
    while queue:
        name = queue.pop()
        if name in found or name.startswith(other):
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
    """Compile the .c files of ``sources_folder`` into ``output`` for ``platform`` (an FMI 2.0
    folder name or FMI 3.0 tuple, :mod:`.cross_build`); returns None or why it could not."""
    return compile_shared(target(platform), sources_folder, output)


def exact_starts(model_name, resources_folder):
    """The derived starts of the C family's FMU ``model_name``: (starts, defaults), where
    starts is {variable name: value} of every variable of its pythonfmu slave as the slave
    starts (exact floats) and defaults the wire parameters the slave exposes
    ({name: value}, or None if it exposes none).

    The slave (:attr:`~sma_fmu.fmi.models.Declaration.slave_path`) runs in this process over
    ``resources_folder``, the pythonfmu twin's unpacked ``resources/`` (its
    ``parameters.json``, and ``signals.json`` where it has one): one interface, one set of
    start values for both families. The FMI 2.0 and 3.0 builds write them into the C FMU's
    model description and ``resources/model_starts.json``.
    """
    path = declaration(model_name).slave_path
    spec = util.spec_from_file_location(f"_sma_native_{model_name}", path)
    module = util.module_from_spec(spec)
    spec.loader.exec_module(module)
    slave = getattr(module, model_name)(instance_name="describe", resources=str(resources_folder))
    starts = {v.name: getattr(slave, v.name) for v in slave.vars.values()}
    defaults = slave.interface.defaults if slave.interface.exposed else None
    return starts, defaults


def _build_one(model_name, python_fmu, folder, work, compile=False, step=None):
    """Write ``folder/<model_name>.fmu`` from the pythonfmu FMU; returns [warning texts].
    ``step(text)``: called before each platform's binary (a progress bar's step)."""
    unpacked = work / model_name
    with zipfile.ZipFile(python_fmu) as archive:
        archive.extractall(unpacked)
    starts, defaults = exact_starts(model_name, unpacked / "resources")
    header_name = f"{model_name}_variables.h"
    names = model_sources(model_name, generated=(header_name,))
    python_description = (unpacked / "modelDescription.xml").read_bytes()
    description, _ = native_description(python_description, starts,
                                        [name for name in names if name.endswith(".c")])
    sources = work / f"{model_name}.sources"
    sources.mkdir()
    files = c_source_files()
    for name in names:
        if name != header_name:
            shutil.copyfile(files[name], sources / name)
    (sources / header_name).write_text(variables_header(description), encoding="utf-8")
    binaries, problems, entries = {}, [], []
    digest = sources_digest({path.name: path.read_bytes() for path in sources.iterdir()})
    for entry in fmi2_targets():
        binary = f"binaries/{entry.fmi2}/{model_name}{entry.suffix}"
        data = None if compile else find_prebuilt(model_name, entry.fmi2, digest)
        if step is not None:
            step(f"{model_name} {entry.fmi2}{' (prebuilt)' if data is not None else ''}")
        if data is None:
            output = work / entry.fmi2 / f"{model_name}{entry.suffix}"
            output.parent.mkdir(exist_ok=True)
            problem = compile_binary(entry.fmi2, sources, output)
            if problem:
                problems.append(f"{model_name}: built without {entry.fmi2}: {problem}")
                continue
            data = output.read_bytes()
        binaries[binary] = data
        if NATIVE_MARKER not in binaries[binary]:
            raise RuntimeError(f"{binary}: the native marker is missing (fmi2_functions.c)")
        entries.append(PlatformEntry(entry.fmi2, binary, front=False, python="none (native C)",
                                     native=True, runs=RUNS_HERE[entry.runs]))
    text = annotate(description.decode("utf-8"), entries)
    fmu = folder / f"{model_name}.fmu"
    with zipfile.ZipFile(fmu, "w", zipfile.ZIP_DEFLATED) as archive:
        archive.writestr("modelDescription.xml", text)
        for name in names:
            archive.write(sources / name, f"sources/{name}")
        for binary, data in binaries.items():
            archive.writestr(binary, data)
        archive.write(unpacked / "resources" / "parameters.json", "resources/parameters.json")
        archive.writestr("resources/model_starts.json", model_starts(description, starts, defaults))
        for extra in sorted((unpacked / "extra").rglob("*")) if (unpacked / "extra").is_dir() else ():
            if extra.is_file():  # the twin's reference result (fmi-ls-ref): the same numbers
                archive.write(extra, extra.relative_to(unpacked).as_posix())
    if (unpacked / MANIFEST).is_file():
        add_documentation(fmu)  # documentation/ of this FMU, from the twin's reference (extras.py)
    fix_timestamps(fmu)  # reproducible.py: the same inputs, the same bytes
    return problems


def build_from_twins(out_dir, parameter_file, names, build_one, platforms, label):
    """Build each C-family FMU of ``names`` (default: every registered one) from its pythonfmu
    twin (the variables, units and exact starts: one interface for both families) into ``out_dir``;
    ``build_one(name, twin path, staging folder, work folder, step)`` writes one FMU, calling
    ``step(text)`` before each of its ``platforms`` (their number), and returns its problem
    texts. A progress bar ``label`` counts the binaries. Built beside ``out_dir`` and moved
    there at the end (a failed build leaves it as it was); returns (names, the distinct
    problems without their model names)."""
    names = [declared.name for declared in declarations()] if names is None else list(names)
    with tempfile.TemporaryDirectory(prefix="sma_fmu_native_") as work:
        work = Path(work)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", FrontWarning)  # the twins' fronts: not shipped
            python_fmus = build_pythonfmu_fmus(work / "python", parameter_file, names,
                                               label="pythonfmu twins")
        problems = []
        with staged_folder(out_dir) as folder, \
                progress.bar(len(names) * platforms, label, unit="binary") as shown:
            def step(text):
                shown.set_postfix_str(text)
                if shown.n < len(names) * platforms:
                    shown.update(1)
            for name in names:
                problems += build_one(name, python_fmus[name], folder, work, step)
    return names, sorted(set(problem.split(": ", 1)[1] for problem in problems))


def build_native_fmus(out_dir, parameter_file=None, names=None, compile=False):
    """Build the native FMUs (default: all five) into ``out_dir``; return {name: path}.

    Each platform's binary is the prebuilt one of the wheel when it was compiled from the
    same sources (:mod:`.prebuilt`), else, or with ``compile``, compiled here.

    Built beside ``out_dir`` and moved there at the end: a failed build leaves it as it was.
    """

    names, problems = build_from_twins(
        out_dir, parameter_file, names,
        lambda name, twin, folder, work, step: _build_one(name, twin, folder, work, compile, step),
        len(fmi2_targets()), "native FMUs (FMI 2.0)")
    for message in problems:
        hint = " Their sources/ compile there: fmpy.build.build_platform_binary"
        if message.startswith("built without win64"):
            hint = " Install mingw-w64 (Debian: apt-get install gcc-mingw-w64-x86-64) or set SMA_FMU_WIN64_CC," + hint
        warnings.warn(NativeBuildWarning(f"native FMUs {message}.{hint}"), stacklevel=2)
    return {name: Path(out_dir) / f"{name}.fmu" for name in names}
