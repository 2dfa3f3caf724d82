"""Fixtures of the system tests (SSP, container, their hosts)."""
import pytest


@pytest.fixture(scope="session")
def fmu_dir(fmus):
    """The folder of the session's pythonfmu FMUs (the conftest's ``fmus``), as ``--fmus`` takes it."""
    return fmus["SmaActuator"].parent
