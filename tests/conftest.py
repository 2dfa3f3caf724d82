"""Shared fixtures: the reference wire's parameters, the FMUs built once per session, the C host,
a wine64 prefix; the ``needs`` marker of tests/support/system_needs.py."""
import os
import subprocess

import pytest

from sma_fmu import load_parameter_set
from system_needs import need, wine_command


def pytest_configure(config):
    config.addinivalue_line("markers", "needs(*names): system packages or root the test needs "
                                       "(tests/support/system_needs.py): skipped without, failed "
                                       "under CI=true")


def pytest_runtest_setup(item):
    """The ``needs`` markers, before any fixture is set up (a missing compiler costs no build)."""
    names = [name for marker in reversed(list(item.iter_markers("needs"))) for name in marker.args]
    if names:
        need(*dict.fromkeys(names))  # every missing one named, module's first


@pytest.fixture(scope="session")
def parameter_set():
    return load_parameter_set()


@pytest.fixture(scope="session")
def params(parameter_set):
    return parameter_set.params


@pytest.fixture(scope="session")
def fmus(tmp_path_factory):
    """The FMUs, built once per test session from the reference parameter file, with the
    C front: the tests of them test the front too, so without a C compiler they skip."""
    need("gcc")
    from sma_fmu.fmi.packaging.build import build_fmus
    return build_fmus(tmp_path_factory.mktemp("fmus"))


@pytest.fixture(scope="session")
def native_fmus(tmp_path_factory):
    """The native (C) FMUs, built once per session (sma-fmu build --native): {name: path}."""
    need("gcc")
    from sma_fmu.fmi.packaging.c_family_build import build_native_fmus
    return build_native_fmus(tmp_path_factory.mktemp("native_fmus"))


@pytest.fixture(scope="session")
def native_dir(native_fmus):
    """The folder of :func:`native_fmus` (what ``--fmus`` takes)."""
    return native_fmus["SmaActuator"].parent


@pytest.fixture(scope="session")
def fmi3_fmus(tmp_path_factory):
    """The native FMUs as FMI 3.0, built once per session (sma-fmu build --native --fmi 3):
    {name: path}."""
    need("gcc")
    from sma_fmu.fmi.packaging.build import build_fmus
    return build_fmus(tmp_path_factory.mktemp("fmi3"), native=True, fmi_version=3)


@pytest.fixture(scope="session")
def unpacked(fmus, tmp_path_factory):
    """Both FMUs unpacked once per session: {name: folder}."""
    from fmi_host import unpack
    root = tmp_path_factory.mktemp("unpacked")
    return {name: unpack(path, root / name) for name, path in fmus.items()}


@pytest.fixture(scope="session")
def fmi_host_exe(tmp_path_factory):
    """sma_fmu/fmi/hosts/fmi_host.c compiled once per session (a plain C FMI host)."""
    need("gcc")
    from sma_fmu.fmi.hosts import compile_host
    return compile_host("fmi_host", tmp_path_factory.mktemp("fmi_host"))


@pytest.fixture(scope="module")
def wine(tmp_path_factory):
    """The environment of a wine64 prefix of the test module's own (Debian's wine64 runs the
    win64 binaries; Z: is /)."""
    need("wine64")
    root = tmp_path_factory.mktemp("wine")
    environment = {k: v for k, v in os.environ.items() if k not in ("LD_PRELOAD", "SMA_FMU_LIBPYTHON")}
    environment.update(WINEPREFIX=str(root / "prefix"), WINEDEBUG="-all", DISPLAY="")
    subprocess.run([wine_command(), "wineboot", "--init"], env=environment, capture_output=True,
                   timeout=600, check=True)
    return environment
