"""Shared fixtures: the reference wire's parameters, loaded once per session."""
import pytest

from sma_fmu import load_parameter_set


@pytest.fixture(scope="session")
def parameter_set():
    return load_parameter_set()


@pytest.fixture(scope="session")
def params(parameter_set):
    return parameter_set.params
