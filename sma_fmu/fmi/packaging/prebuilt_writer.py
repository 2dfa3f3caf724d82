"""Filling the prebuilt folder of :mod:`.prebuilt` (the build backend, before the wheel is built):
``python -m sma_fmu.fmi.packaging.prebuilt_writer [--out DIR]``; without ``--out`` it also
writes the prebuilt C hosts (:func:`sma_fmu.fmi.hosts.write_prebuilt_hosts`: what
``sma-fmu check`` runs where no C compiler is)."""
import argparse
import json
import shutil
import sys
import tempfile
import warnings
import zipfile
from pathlib import Path

from sma_fmu.fmi.hosts import CHostError, write_prebuilt_hosts
from sma_fmu.fmi.packaging.c_family_build import build_native_fmus
from sma_fmu.fmi.packaging.cross_build import TARGETS, fmi2_targets
from sma_fmu.fmi.packaging.fmi3_build import build_fmi3_fmus
from sma_fmu.fmi.packaging.prebuilt import FRONTS, MANIFEST, PREBUILT, fmi3_key, sources_digest

__all__ = ["write_prebuilt", "main"]


def _write_fronts(folder):
    """The Python family's fronts, compiled recording no build libpython: their manifest entry."""
    from sma_fmu.fmi.hosts import c_compiler, windows_compiler
    from sma_fmu.fmi.packaging.front_build import _LINUX, _WINDOWS, _compile_cached, _sources

    binaries = {}
    for platform, (compiler, target) in {"linux64": (c_compiler(), _LINUX),
                                         "win64": (windows_compiler(), _WINDOWS)}.items():
        build = _compile_cached(compiler, target, [])
        if build.library is None:
            raise RuntimeError(f"prebuilt front for {platform}: {build.problem}")
        (folder / "front" / platform).mkdir(parents=True)
        (folder / "front" / platform / FRONTS[platform]).write_bytes(build.library)
        binaries[platform] = FRONTS[platform]
    return {"sources": sources_digest(_sources()), "binaries": binaries}


def _keep_binaries(fmu, folder, key, platforms):
    """Copy the FMU's binaries of ``platforms`` ({binaries/ folder name: suffix}) to
    ``folder/key/<platform>/``; their manifest entry."""
    model = Path(fmu).stem
    with zipfile.ZipFile(fmu) as archive:
        sources = {n.split("/", 1)[1]: archive.read(n) for n in archive.namelist()
                   if n.startswith("sources/") and n != "sources/"}
        binaries = {}
        for platform, suffix in platforms.items():
            name = f"{model}{suffix}"
            (folder / key / platform).mkdir(parents=True)
            (folder / key / platform / name).write_bytes(archive.read(f"binaries/{platform}/{name}"))
            binaries[platform] = name
    return {"sources": sources_digest(sources), "binaries": binaries}


def write_prebuilt(folder=PREBUILT):
    """Compile the five models for every FMI 2.0 platform (``build --native --compile``) and
    every FMI 3.0 one (``--fmi 3``) and keep their binaries in ``folder``; returns
    {model or fmi3_key(model): [platforms]}. Raises RuntimeError if a platform has no
    compiler here (the wheel must carry them all)."""
    folder = Path(folder)
    with tempfile.TemporaryDirectory(prefix="sma_fmu_prebuilt_") as work:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            fmus = build_native_fmus(Path(work) / "fmus", compile=True)
            fmi3_fmus = build_fmi3_fmus(Path(work) / "fmi3", compile=True)
        problems = [str(w.message) for w in caught if "built without" in str(w.message)]
        if problems:
            raise RuntimeError("prebuilt binaries: " + "; ".join(problems))
        if folder.exists():
            shutil.rmtree(folder)
        folder.mkdir(parents=True)
        manifest = {}
        for model, path in fmus.items():
            manifest[model] = _keep_binaries(path, folder, model,
                                             {entry.fmi2: entry.suffix for entry in fmi2_targets()})
        for model, path in fmi3_fmus.items():
            manifest[fmi3_key(model)] = _keep_binaries(path, folder, fmi3_key(model),
                                                       {name: t.suffix for name, t in TARGETS.items()})
    manifest["front"] = _write_fronts(folder)
    (folder / MANIFEST).write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n",
                                   encoding="utf-8")
    return {model: sorted(entry["binaries"]) for model, entry in manifest.items()}


def main(argv=None):
    """Fill the prebuilt folder (``--out``, default :data:`~.prebuilt.PREBUILT`); 1 on failure."""
    parser = argparse.ArgumentParser(prog="python -m sma_fmu.fmi.packaging.prebuilt_writer",
                                     description="compile the C family's prebuilt binaries")
    parser.add_argument("--out", type=Path, default=PREBUILT, metavar="DIR")
    args = parser.parse_args(argv)
    try:
        built = write_prebuilt(args.out)
        if args.out == PREBUILT:
            print(f"C hosts: {write_prebuilt_hosts()}")
    except (RuntimeError, CHostError) as error:
        print(f"prebuilt: {error}", file=sys.stderr)
        return 1
    for model, platforms in built.items():
        print(f"{model}: {', '.join(platforms)}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
