"""The shared real isobaric files (../shared/data/real-isobaric/ seen from the project root):
public data without a licence, read in place and never copied into the project. Where a
folder is absent the tests that need it skip naming it; under CI=true they fail instead."""
import os
from pathlib import Path

import pytest

__all__ = ["REAL", "real_folder"]

REAL = Path(__file__).resolve().parents[2].parent / "shared" / "data" / "real-isobaric"


def real_folder(name):
    """The folder ``name`` of the shared real files (skip, or fail under CI=true, without it)."""
    folder = REAL / name
    if not folder.is_dir():
        if os.environ.get("CI") == "true":
            pytest.fail(f"the shared real isobaric data are missing: {folder}")
        pytest.skip(f"the shared real isobaric data are not here: {folder}")
    return folder
