"""Fixtures of the host and platform tests: the plant unpacked once per module, and fmusim,
the by-hand checks' simulator."""
import pytest

from fmi_host import unpack
from system_needs import by_hand_executable


@pytest.fixture(scope="module")
def plant_folder(fmus, tmp_path_factory):
    """The session's SmaActuator FMU unpacked into a folder of the module's own."""
    return unpack(fmus["SmaActuator"], tmp_path_factory.mktemp("plant"))


@pytest.fixture(scope="module")
def fmusim():
    """The executable SMA_FMU_FMUSIM names; a missing one fails the check."""
    return by_hand_executable("SMA_FMU_FMUSIM", "an fmusim executable of Reference-FMUs v0.0.39")
