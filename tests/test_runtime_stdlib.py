"""The runtime package (shipped inside the FMUs) imports only the standard library."""
import ast
import subprocess
import sys
from pathlib import Path

import sma_fmu.runtime

RUNTIME = Path(sma_fmu.runtime.__file__).parent


def test_runtime_imports_only_stdlib_and_itself():
    allowed = set(sys.stdlib_module_names)
    for path in sorted(RUNTIME.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.Import):
                roots = [alias.name.split(".")[0] for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                roots = [] if node.level > 0 else [node.module.split(".")[0]]
            else:
                continue
            for root in roots:
                assert root in allowed, f"{path.name} imports {root}"


def test_runtime_runs_with_numpy_blocked():
    """Import and use every runtime module in a fresh interpreter where numpy cannot load."""
    code = (
        "import sys; sys.modules['numpy'] = None; sys.modules['scipy'] = None\n"
        "import importlib, pkgutil, sma_fmu.runtime as rt\n"
        "for m in pkgutil.iter_modules(rt.__path__): importlib.import_module('sma_fmu.runtime.' + m.name)\n"
        "from sma_fmu.runtime.parameters import WireParameters\n"
        "from sma_fmu.runtime.plant import PlantStepper\n"
        "assert 'numpy' not in [k for k, v in sys.modules.items() if v is not None]\n"
        "print('ok')\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"
