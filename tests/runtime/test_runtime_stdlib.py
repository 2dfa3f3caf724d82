"""The runtime package (shipped inside the FMUs) imports only the standard library."""
import subprocess
import sys
from pathlib import Path

import sma_fmu.runtime
from import_roots import imported_roots

RUNTIME = Path(sma_fmu.runtime.__file__).parent



def test_runtime_imports_only_stdlib_and_itself():
    allowed = set(sys.stdlib_module_names)
    for path in sorted(RUNTIME.glob("*.py")):
        roots = imported_roots(path.read_text(encoding="utf-8"))
        assert roots <= allowed, f"{path.name} imports {sorted(roots - allowed)}"


def _run_blocked(blocked, body):
    code = "import sys\n" + "".join(f"sys.modules[{name!r}] = None\n" for name in blocked) + body
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "ok"


def test_library_runtime_runs_without_numpy_scipy_or_pythonfmu():
    """Every runtime module imports and steps with those packages unavailable."""
    _run_blocked(["numpy", "scipy", "pythonfmu"], (
        "import importlib, pkgutil, sma_fmu.runtime as rt\n"
        "for m in pkgutil.iter_modules(rt.__path__):\n"
        "    importlib.import_module('sma_fmu.runtime.' + m.name)\n"
        "from sma_fmu.runtime.parameters import WireParameters\n"
        "from sma_fmu.runtime.plant import PlantStepper\n"
        "print('ok')\n"))


def test_slave_support_needs_only_pythonfmu_besides_stdlib():
    _run_blocked(["numpy", "scipy"], "import sma_fmu.fmi.python_family.slave_support.interface\nprint('ok')\n")
