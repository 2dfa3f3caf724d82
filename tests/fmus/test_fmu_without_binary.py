"""An FMU without a binary for the platform it runs on (a native FMU built where no compiler
was, its sources only) is refused naming the FMU, the platform and what to do: one error,
not fmpy's bare exception (which the command line showed as an internal error)."""
import zipfile

import pytest
from fmpy import platform

from sma_fmu.fmi.driving.instance import FmuError, FmuInstance


def test_an_fmu_without_this_platforms_binary_is_a_named_error(fmus, tmp_path):
    bare = tmp_path / "SmaPiController.fmu"
    with zipfile.ZipFile(fmus["SmaPiController"]) as source, \
            zipfile.ZipFile(bare, "w", zipfile.ZIP_DEFLATED) as target:
        kept = [item for item in source.infolist()
                if not item.filename.startswith(f"binaries/{platform}/")]
        assert len(kept) < len(source.infolist())      # it had one, and it is gone
        for item in kept:
            target.writestr(item, source.read(item))
    with pytest.raises(FmuError) as raised:
        FmuInstance(bare, "pi")
    assert str(raised.value).startswith(f"{bare}: the FMU has no binary for this platform "
                                        f"({platform}); build it here")
    assert raised.value.status == 3
