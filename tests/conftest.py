"""Shared fixtures: the reference wire's parameters, loaded once per session."""
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
