"""The package's layout shows its architecture: no loose module at the top, and every import
between subpackages goes down the layers (so there is no package cycle either)."""
import ast
from pathlib import Path

import sma_fmu

ROOT = Path(sma_fmu.__file__).parent
# lowest first; a subpackage may import only those before it (studies, analysis and
# identification are side by side: none imports another)
LAYERS = [{"runtime"}, {"files"}, {"wire"}, {"fmi"}, {"cosim"}, {"systems"},
          {"studies", "analysis", "identification"}, {"bench"}, {"cli"}]
LEVEL = {name: level for level, names in enumerate(LAYERS) for name in names}
DATA = {"models", "scenarios", "examples"}   # data folders (examples are user scripts)


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
