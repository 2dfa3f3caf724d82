"""Shared fixtures: the reference wire's parameters, the FMUs built once per session, the C host."""
import pytest

from sma_fmu import load_parameter_set


@pytest.fixture(scope="session")
def parameter_set():
    return load_parameter_set()


@pytest.fixture(scope="session")
def params(parameter_set):
    return parameter_set.params


@pytest.fixture(scope="session")
def fmus(tmp_path_factory):
    """Both FMUs, built once per test session from the reference parameter file."""
    from sma_fmu.fmi.build import build_fmus
    return build_fmus(tmp_path_factory.mktemp("fmus"))


@pytest.fixture(scope="session")
def unpacked(fmus, tmp_path_factory):
    """Both FMUs unpacked once per session: {name: folder}."""
    from fmi_host import unpack
    root = tmp_path_factory.mktemp("unpacked")
    return {name: unpack(path, root / name) for name, path in fmus.items()}


@pytest.fixture(scope="session")
def fmi_host_exe(tmp_path_factory):
    """sma_fmu/fmi/hosts/fmi_host.c compiled once per session (a plain C FMI host)."""
    from sma_fmu.fmi.hosts import compile_host
    return compile_host("fmi_host", tmp_path_factory.mktemp("fmi_host"))
