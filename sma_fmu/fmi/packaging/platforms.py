"""Which platforms an FMU runs on, and what it says about them.

An FMU lists a platform by carrying ``binaries/<platform>/``. Ours list one only where the
binary is the C front (:mod:`sma_fmu.fmi.packaging.front_build`), or, where the front could not be
built, say so: the ``sma-fmu`` entry of ``VendorAnnotations`` in ``modelDescription.xml``
names each platform, its binary, whether it carries the front, how it finds Python, and
what is degraded without the front. :func:`platform_report` reads it back
(``sma-fmu check``'s ``platforms`` line), :func:`check_build_machine` refuses a build whose
architecture pythonfmu's binaries do not match.
"""
import platform
import re
import struct
import zipfile
from dataclasses import dataclass
from importlib import util
from pathlib import Path
from xml.sax.saxutils import quoteattr

__all__ = ["FRONT_MARKER", "PLATFORMS", "PLATFORMS_FILE", "DEGRADED", "UnsupportedPlatformError", "PlatformEntry",
           "binary_architecture", "check_build_machine", "annotate", "platform_report",
           "platform_results"]

FRONT_MARKER = b"sma-fmu native front"  # a string every front binary carries (fmi2_exports.c);
# its old words are kept so FMUs built before the word "native" came to mean the C family still count
NATIVE_MARKER = b"sma-fmu native C FMU"  # ... every C-family binary (c_family/core/layer_calls.c)
PLATFORMS = {"linux64": ".so", "win64": ".dll", "darwin64": ".dylib", "win32": ".dll"}
# FMI 3.0's platform tuples (the C family's FMI 3.0 FMUs) and their binaries' suffixes
FMI3_PLATFORMS = {"x86_64-linux": ".so", "aarch64-linux": ".so", "x86_64-windows": ".dll",
                  "x86-windows": ".dll", "x86_64-darwin": ".dylib", "aarch64-darwin": ".dylib"}
HOW_PYTHON_IS_FOUND = {
    "linux64": "the process's own Python, else $SMA_FMU_LIBPYTHON, else the build's libpython, "
               "else the newest libpython3.X.so.1.0 (3.10 or newer) on the library search path "
               "and in the standard folders",
    "win64": "the process's own python3X.dll, else %SMA_FMU_LIBPYTHON%, else the newest Python "
             "3.10 or newer in the registry (PEP 514), on PATH or in the python.org installer's "
             "folders",
}
DEGRADED = ("pythonfmu's binary without the C front: C hosts need libpython in LD_PRELOAD; "
            "refused calls return fmi2OK (the log is the only signal); no checks of the resource "
            "URI, the GUID, strings or state pointers (crashes instead); serialized states "
            "without checksum; fmi2Terminated true for good after any discard; no check of the "
            "Python version; each instance keeps its copy of the binary in memory")
_ELF_MACHINES = {62: "x86-64", 183: "aarch64", 3: "x86", 40: "arm"}
_PE_MACHINES = {0x8664: "x86-64", 0xAA64: "aarch64", 0x14C: "x86"}
_MACHO_MACHINES = {0x01000007: "x86-64", 0x0100000C: "aarch64"}
_MACHINES = {"x86_64": "x86-64", "amd64": "x86-64", "aarch64": "aarch64", "arm64": "aarch64",
             "i386": "x86", "i686": "x86", "x86": "x86"}
_TOOL = "sma-fmu"
# FMI 3.0 C-family FMUs list their platforms here rather than in a top-level <Annotations> of
# modelDescription.xml: valid by the FMI 3.0 schema, but the FMI Library 3.0.4 (under
# OMSimulator, libcosim and other C tools) logs an error for it (docs/systems.md)
PLATFORMS_FILE = "extra/org.sma-fmu.platforms/platforms.xml"


class UnsupportedPlatformError(ValueError):
    """This machine cannot build FMUs that run on it (pythonfmu has no binary for it)."""


@dataclass(frozen=True)
class PlatformEntry:
    """One platform of an FMU: its binary, whether that is the front, and what it says."""

    platform: str
    binary: str
    front: bool
    python: str = ""
    degraded: str = ""
    native: bool = False  # a C-family binary (sma-fmu build --native): no Python at all
    runs: str = ""        # how the tests run it (cross_build.RUNS_HERE): natively, wine, qemu, only built


def binary_architecture(data):
    """"x86-64", "aarch64", ... of an ELF, PE or 64-bit Mach-O binary's bytes; None if none."""
    if data[:4] == b"\xcf\xfa\xed\xfe" and len(data) >= 8:
        return _MACHO_MACHINES.get(struct.unpack_from("<I", data, 4)[0], "unknown")
    if data[:4] == b"\x7fELF" and len(data) >= 20:
        return _ELF_MACHINES.get(struct.unpack_from("<H", data, 18)[0], "unknown")
    if data[:2] == b"MZ" and len(data) >= 64:
        offset = struct.unpack_from("<I", data, 0x3C)[0]
        if data[offset:offset + 4] == b"PE\0\0":
            return _PE_MACHINES.get(struct.unpack_from("<H", data, offset + 4)[0], "unknown")
    return None


def _pythonfmu_binaries():
    """{platform: path} of the binaries pythonfmu copies into every FMU."""
    spec = util.find_spec("pythonfmu")
    folder = Path(spec.origin).parent / "resources" / "binaries"
    return {entry.name: file for entry in sorted(folder.iterdir()) if entry.is_dir()
            for file in sorted(entry.iterdir()) if file.suffix in (".so", ".dll", ".dylib")}


def check_build_machine(machine=None):
    """Raise :class:`UnsupportedPlatformError` unless pythonfmu's binaries match ``machine``.

    ``machine`` defaults to this machine (``platform.machine()``). The front is compiled for
    the build machine and sits before pythonfmu's binary of the same platform, so a machine
    of another architecture would pair them wrongly and build FMUs that run nowhere.
    """
    machine = machine or platform.machine()
    architecture = _MACHINES.get(machine.lower(), machine)
    shipped = {name: binary_architecture(path.read_bytes()[:4096])
               for name, path in _pythonfmu_binaries().items()}
    if architecture not in shipped.values():
        listed = ", ".join(f"{name}: {arch}" for name, arch in shipped.items())
        raise UnsupportedPlatformError(
            f"this machine is {machine} ({architecture}), but pythonfmu 0.7.0 ships binaries for "
            f"{listed} only: an FMU built here would pair a {architecture} front with "
            f"pythonfmu's binary of another architecture and run nowhere. Build the FMUs on an "
            f"x86-64 machine.")


def annotate(model_description, entries):
    """``model_description`` (XML text) with the sma-fmu VendorAnnotations for ``entries``
    (a list of :class:`PlatformEntry`), or without them (``entries`` None)."""
    text = re.sub(rf'\t*<Tool name="{_TOOL}">.*?</Tool>\n', "", model_description, flags=re.S)
    text = re.sub(r"\t*<VendorAnnotations>\n\t*</VendorAnnotations>\n", "", text)
    if entries is None:
        return text
    lines = [f'\t\t<Tool name="{_TOOL}">', "\t\t\t<Platforms>"]
    for entry in entries:
        attributes = (f"name={quoteattr(entry.platform)} binary={quoteattr(entry.binary)} "
                      f"front=\"{str(entry.front).lower()}\" python={quoteattr(entry.python)}")
        if entry.degraded:
            attributes += f" degraded={quoteattr(entry.degraded)}"
        if entry.native:
            attributes += ' native="true"'
        if entry.runs:
            attributes += f" tested={quoteattr(entry.runs)}"
        lines.append(f"\t\t\t\t<Platform {attributes}/>")
    lines += ["\t\t\t</Platforms>", "\t\t</Tool>"]
    block = "\n".join(lines) + "\n"
    if "<VendorAnnotations>" in text:
        return text.replace("<VendorAnnotations>\n", "<VendorAnnotations>\n" + block, 1)
    if "<ModelVariables" not in text:
        raise ValueError("modelDescription.xml has no ModelVariables element")
    return text.replace("\t<ModelVariables", f"\t<VendorAnnotations>\n{block}\t</VendorAnnotations>\n"
                        "\t<ModelVariables", 1)


def _declared(model_description, archive, names):
    """{platform: attributes} from the sma-fmu VendorAnnotations (FMI 2.0) or the FMU's
    PLATFORMS_FILE (FMI 3.0), {} if there are none."""
    import xml.etree.ElementTree as ET

    root = ET.fromstring(model_description)
    found = {node.get("name"): dict(node.attrib)
             for tool in root.iterfind("VendorAnnotations/Tool") if tool.get("name") == _TOOL
             for node in tool.iterfind("Platforms/Platform")}
    if PLATFORMS_FILE in names:
        listed = ET.fromstring(archive.read(PLATFORMS_FILE))
        found.update({node.get("name"): dict(node.attrib) for node in listed.iterfind("Platform")})
    return found


def _declaring_file(names):
    """The file of the FMU that declares its platforms (for messages)."""
    return PLATFORMS_FILE if PLATFORMS_FILE in names else "modelDescription.xml"


def platform_report(fmu_path):
    """[(status, platform, detail)] for each platform the FMU ``fmu_path`` lists.

    status is "ok" (the binary is the front and the model description says so), "warn" (no
    front, and the model description says what is degraded), "FAIL" (the binaries and the
    model description disagree, or an FMU of an earlier ``sma-fmu build`` lists platforms it
    does not declare), or, once for the whole FMU, "n/a" when ``sma-fmu build`` did not
    make it (a container, another tool's FMU).
    """
    import xml.etree.ElementTree as ET

    with zipfile.ZipFile(fmu_path) as archive:
        names = archive.namelist()
        description = archive.read("modelDescription.xml").decode("utf-8")
        declared = _declared(description, archive, names)
        if not declared and not _built_by_sma_fmu(archive, names):
            return [("n/a", "all", "not built by sma-fmu build (a container, another tool's FMU)")]
        root = ET.fromstring(description)
        kinds = [root.find(kind) for kind in ("CoSimulation", "ModelExchange")]
        identifier = next(kind.get("modelIdentifier") for kind in kinds if kind is not None)
        listed = sorted({name.split("/")[1] for name in names if name.startswith("binaries/")
                         and name.count("/") >= 2 and name.split("/")[2]})
        return [_platform_line(archive, names, identifier, name, declared.get(name))
                for name in listed] + \
            [("FAIL", name, f"declared in {_declaring_file(names)} but not in binaries/")
             for name in sorted(set(declared) - set(listed))]


def _built_by_sma_fmu(archive, names):
    """True for an FMU of ``sma-fmu build``, annotated or not (an earlier build)."""
    return "resources/parameters.json" in names and \
        b'"sma_fmu_version"' in archive.read("resources/parameters.json")


def _platform_line(archive, names, identifier, name, said):
    source = _declaring_file(names)
    binary = f"binaries/{name}/{identifier}{PLATFORMS.get(name) or FMI3_PLATFORMS.get(name, '')}"
    if binary not in names:
        return "FAIL", name, f"lists the platform but has no {binary}"
    data = archive.read(binary)
    front = FRONT_MARKER in data
    what = f"{binary} ({binary_architecture(data) or 'unknown format'})"
    if said is not None and said.get("native") == "true":
        if NATIVE_MARKER not in data:
            return "FAIL", name, f"{source} says native, but {what} is no sma-fmu C-family binary"
        tested = f"; {said['tested']}" if said.get("tested") else ""
        return "ok", name, f"{what}: native C (sma-fmu build --native), no Python{tested}"
    if said is None:
        return "FAIL", name, f"{what}, {'the front' if front else 'without this front'}, is not " \
                             f"declared in {source}"
    if (said.get("front") == "true") != front:
        return "FAIL", name, f"{source} says front={said.get('front')}, but {what} " \
                             f"is {'the front' if front else 'not the front'}"
    if front:
        return "ok", name, f"{what}: C front; Python: {said.get('python')}"
    if said.get("degraded"):
        return "warn", name, f"{what}: degraded: {said['degraded']}"
    return "FAIL", name, f"{what} has no front and {source} does not say what is degraded"


def platform_results(path):
    """[(label, status, detail)] of an FMU, or of each FMU in an SSP package (``sma-fmu check``)."""
    path = Path(path)
    if not zipfile.is_zipfile(path):
        return []
    if path.suffix.lower() != ".ssp":
        return [(f"platform {name}", status, detail) for status, name, detail in platform_report(path)]
    import tempfile

    from sma_fmu.files.archives import require_safe_archive

    require_safe_archive(path)  # its FMUs are unpacked below
    results = []
    with tempfile.TemporaryDirectory(prefix="sma_fmu_platforms_") as folder, zipfile.ZipFile(path) as ssp:
        for name in sorted(n for n in ssp.namelist() if n.lower().endswith(".fmu")):
            inner = ssp.extract(name, folder)
            results += [(f"[{name}] platform {platform_name}", status, detail)
                        for status, platform_name, detail in platform_report(inner)]
    return results
