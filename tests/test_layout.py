"""The package's layout shows its architecture: no loose module at the top, every import
between subpackages goes down the layers (so there is no package cycle either), a concern of
four modules or more is a subpackage, not a name prefix, and no module is over 400 lines."""
import ast
from collections import defaultdict
from pathlib import Path

import pytest

import sma_fmu

ROOT = Path(sma_fmu.__file__).parent
# lowest first; a subpackage may import only those before it (studies, analysis and
# identification are side by side: none imports another)
LAYERS = [{"runtime"}, {"files"}, {"wire"}, {"fmi"}, {"cosim"}, {"systems"},
          {"studies", "analysis", "identification"}, {"bench"}, {"cli"}]
LEVEL = {name: level for level, names in enumerate(LAYERS) for name in names}
DATA = {"models", "scenarios", "examples"}   # data folders (examples are user scripts)
FAMILY_SIZE = 4        # modules sharing a name prefix ("isobaric_*") that make a subpackage
MAX_LINES = 400        # a module over this is split along its seams (house style: ~300)
# folder (relative to the package) -> (prefix, why it may stay a family)
PREFIX_EXCEPTIONS = {"fmi/slaves": ("sma", "pythonfmu slave scripts, one FMU each, named after "
                                           "their model class (SmaActuator ...); not imported")}
LONG_MODULE_EXCEPTIONS = {}   # path -> why it may stay over MAX_LINES (none now)
SUBPACKAGES = ("identification/isobaric", "studies/batch", "cosim/scenario")   # made in issue 30


def _imports_between_subpackages():
    """{(importing subpackage, imported subpackage, file)} of every sma_fmu import."""
    found = set()
    for path in ROOT.rglob("*.py"):
        parts = path.relative_to(ROOT).parts
        if len(parts) == 1 or parts[0] in DATA:
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                names = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom) and node.level == 0:
                names = [node.module]
            else:
                continue
            for name in names:
                words = name.split(".")
                if words[0] == "sma_fmu" and len(words) > 1 and words[1] != parts[0] \
                        and (ROOT / words[1]).is_dir():
                    found.add((parts[0], words[1], str(path.relative_to(ROOT))))
    return found


def test_the_top_level_holds_no_loose_module():
    loose = sorted(p.name for p in ROOT.glob("*.py") if p.name not in ("__init__.py", "__main__.py"))
    assert loose == []


def test_every_subpackage_has_a_layer():
    packages = {p.name for p in ROOT.iterdir() if p.is_dir() and (p / "__init__.py").exists()}
    assert packages - DATA == set(LEVEL)


def test_imports_go_down_the_layers_only():
    edges = _imports_between_subpackages()
    assert len(edges) > 20            # the walk sees the real imports
    upward = sorted(f"{where}: {source} imports {target}" for source, target, where in edges
                    if LEVEL[target] >= LEVEL[source])
    assert upward == []


def prefix_families(names):
    """{prefix: sorted module names} of the prefixes shared by FAMILY_SIZE or more ``names``
    (module stems): the prefix is the name up to its first underscore; a module named just
    the prefix belongs to its family ("isobaric" beside "isobaric_files")."""
    members = defaultdict(set)
    for name in names:
        members[name.split("_")[0]].add(name)
    return {prefix: sorted(found) for prefix, found in members.items()
            if len(found) >= FAMILY_SIZE and any("_" in name for name in found)}


def _folders():
    """{folder relative to the package: module stems} of every folder holding Python files."""
    folders = defaultdict(list)
    for path in ROOT.rglob("*.py"):
        if "__pycache__" not in path.parts and path.stem not in ("__init__", "__main__"):
            folders[path.parent.relative_to(ROOT).as_posix()].append(path.stem)
    return folders


@pytest.mark.parametrize("names, expected", [
    (["isobaric", "isobaric_files", "isobaric_lag", "isobaric_model", "runner"],
     {"isobaric": ["isobaric", "isobaric_files", "isobaric_lag", "isobaric_model"]}),
    (["batch_plant", "batch_pwm", "batch_inputs", "design"], {}),
    (["constant_load", "constant_length", "constant_temperature", "constants"], {}),
])
def test_a_family_is_four_modules_sharing_a_prefix(names, expected):
    assert prefix_families(names) == expected


def test_no_package_holds_a_family_of_prefixed_modules():
    folders = _folders()
    assert len(folders) > 10 and "identification/isobaric" in folders   # the walk sees the tree
    found = {folder: families for folder, names in sorted(folders.items())
             if (families := prefix_families(names))}
    allowed = {folder: prefix for folder, (prefix, _why) in PREFIX_EXCEPTIONS.items()}
    assert {folder: sorted(families) for folder, families in found.items()} \
        == {folder: [prefix] for folder, prefix in allowed.items()}, found


def test_no_module_is_over_the_line_limit():
    lines = {path.relative_to(ROOT).as_posix(): len(path.read_text(encoding="utf-8").splitlines())
             for path in ROOT.rglob("*.py") if "__pycache__" not in path.parts}
    assert len(lines) > 100 and max(lines.values()) > 100   # the walk counts real modules
    long = sorted(f"{path}: {count} lines" for path, count in lines.items()
                  if count > MAX_LINES and path not in LONG_MODULE_EXCEPTIONS)
    assert long == []
    assert all(lines.get(path, 0) > MAX_LINES for path in LONG_MODULE_EXCEPTIONS)   # none stale


@pytest.mark.parametrize("folder", SUBPACKAGES)
def test_each_concern_is_a_subpackage_with_a_public_face(folder):
    """The subpackage exists, its __init__ says what it holds (docstring) and names its public
    face (__all__), and no stale module of its name is left beside it."""
    init = ROOT / folder / "__init__.py"
    tree = ast.parse(init.read_text(encoding="utf-8"))
    assert ast.get_docstring(tree)
    assert any(isinstance(node, ast.Assign) and any(getattr(target, "id", None) == "__all__"
                                                    for target in node.targets)
               for node in tree.body)
    assert not (ROOT / f"{folder}.py").exists()
