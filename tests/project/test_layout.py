"""The package's layout shows its architecture: no loose module at the top, every import
between subpackages goes down the layers (so there is no package cycle either), a concern of
four modules or more is a subpackage, not a name prefix, and no module is over 400 lines.
The tests' layout too: folders by concern, helpers in tests/support."""
import ast
from collections import defaultdict
from pathlib import Path

import pytest

import sma_fmu
from graph_cycles import find_cycle

ROOT = Path(sma_fmu.__file__).parent
# lowest first; a subpackage may import only those before it (studies, analysis and
# identification are side by side: none imports another)
LAYERS = [{"runtime"}, {"console"}, {"files"}, {"wire"}, {"fmi"}, {"cosim"}, {"systems"},
          {"studies", "analysis", "identification"}, {"bench"}, {"cli"}]
LEVEL = {name: level for level, names in enumerate(LAYERS) for name in names}
DATA = {"models", "scenarios", "examples"}   # data folders (examples are user scripts)
FAMILY_SIZE = 4        # modules sharing a name prefix ("isobaric_*") that make a subpackage
MAX_LINES = 400        # a module over this is split along its seams (house style: ~300)
# folder (relative to the package) -> (prefix, why it may stay a family)
PREFIX_EXCEPTIONS = {}
LONG_MODULE_EXCEPTIONS = {}   # path -> why it may stay over MAX_LINES (none now)
SUBPACKAGES = ("identification/isobaric", "studies/batch", "cosim/scenario")   # made in issue 30
# the rooms of sma_fmu/fmi (issue 37), lowest first: a room imports only from rooms before it
# (models/: one folder per FMU, its slave over python_family, its adapter over c_family)
FMI_ROOMS = ["c_common", "python_family", "c_family", "models", "hosts", "driving", "loop", "packaging"]
TESTS = Path(__file__).parents[1]
# tests/ by concern: a folder of test modules each (and the by-hand *_check.py modules beside
# the tests they import from); support/ holds what is not a test (helpers, C hosts, scripts),
# on sys.path through pyproject.toml's pythonpath
TEST_FOLDERS = {"runtime", "fmus", "native", "hosts", "cosim", "systems", "identification",
                "studies", "bench", "cli", "project", "support"}


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


def _module_name(path):
    parts = list(path.relative_to(ROOT.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


def _module_imports():
    """{module: {sma_fmu modules it imports, at any depth of its code}} (a name imported from a
    package counts as the submodule when there is one)."""
    modules = {_module_name(path): path for path in ROOT.rglob("*.py")
               if "__pycache__" not in path.parts and path.relative_to(ROOT).parts[0] not in DATA}
    graph = {}
    for name, path in modules.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        found = set()
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                targets = [alias.name for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                base = node.module or ""
                if node.level:
                    base = ".".join(package.split(".")[:len(package.split(".")) - node.level + 1]
                                    + ([node.module] if node.module else []))
                targets = [f"{base}.{alias.name}" if f"{base}.{alias.name}" in modules else base
                           for alias in node.names]
            else:
                continue
            found |= {target for target in targets if target in modules and target != name}
        graph[name] = found
    return graph


def test_the_import_check_finds_a_circle():
    assert find_cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


def test_no_circle_of_modules():
    """Modules import one way, imports inside functions included (issue 37: fmi's build.py,
    native_build.py, fmu_documentation.py and fmu_extras.py were a circle)."""
    graph = _module_imports()
    assert sum(map(len, graph.values())) > 200   # the walk sees the real imports
    cycle = find_cycle(graph)
    assert cycle is None, f"modules import each other in a circle: {' -> '.join(cycle)}"


def test_fmi_holds_rooms_only():
    """sma_fmu/fmi has no loose module, its rooms are the pinned ones, and no folder named
    "native" holds the Python family's front ("native" means the C family)."""
    fmi = ROOT / "fmi"
    assert sorted(p.name for p in fmi.glob("*.py")) == ["__init__.py"]
    rooms = sorted(p.name for p in fmi.iterdir() if p.is_dir() and p.name != "__pycache__")
    assert rooms == sorted(FMI_ROOMS)
    assert not [p for p in fmi.rglob("native") if p.is_dir()]
    assert (fmi / "python_family" / "front" / "fmi2_exports.c").is_file()


def test_fmi_rooms_import_down_only():
    level = {room: index for index, room in enumerate(FMI_ROOMS)}
    upward = []
    for name, targets in _module_imports().items():
        words = name.split(".")
        if words[:2] != ["sma_fmu", "fmi"] or len(words) < 4:
            continue
        for target in targets:
            other = target.split(".")
            if other[:2] == ["sma_fmu", "fmi"] and len(other) > 2 and other[2] in level \
                    and other[2] != words[2] and level[other[2]] > level[words[2]]:
                upward.append(f"{name} imports {target}")
    assert sorted(upward) == []
    packaging = _module_imports()["sma_fmu.fmi.packaging.build"]
    assert "sma_fmu.fmi.driving.description" in packaging   # the walk sees the rooms' imports


def test_tests_are_in_their_folders_only():
    """tests/ holds the session's conftest.py and the concern folders; no test module lies
    loose, and support/ holds none."""
    assert sorted(p.name for p in TESTS.glob("*.py")) == ["conftest.py"]
    folders = {p.name for p in TESTS.iterdir() if p.is_dir() and p.name != "__pycache__"}
    assert folders == TEST_FOLDERS
    assert not list((TESTS / "support").glob("test_*.py"))
    assert all(list((TESTS / folder).glob("test_*.py")) for folder in TEST_FOLDERS - {"support"})


def test_test_module_names_are_unique_across_the_folders():
    """pytest imports each test module by its bare name (the folders are not packages), so two
    modules of one name in two folders stop the whole run at collection."""
    seen = defaultdict(list)
    for path in TESTS.glob("*/test_*.py"):
        seen[path.name].append(path.parent.name)
    assert len(seen) > 100   # the walk sees the tests
    assert {name: folders for name, folders in seen.items() if len(folders) > 1} == {}


def test_a_test_module_imports_test_modules_of_its_own_folder_only():
    """pytest puts a test's own folder on sys.path (and tests/support, by pythonpath), so a
    module of another folder imports only when that folder was imported first: by chance."""
    modules = {p.stem: p.parent.name for p in TESTS.glob("*/*.py") if p.parent.name != "support"}
    assert len(modules) > 100   # the walk sees the tests
    strays = []
    for path in TESTS.glob("*/*.py"):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            names = [alias.name for alias in node.names] if isinstance(node, ast.Import) else \
                [node.module] if isinstance(node, ast.ImportFrom) and node.level == 0 else []
            strays += [f"{path.relative_to(TESTS)} imports {name} of {modules[name]}/"
                       for name in names if modules.get(name, path.parent.name) != path.parent.name]
    assert strays == []
