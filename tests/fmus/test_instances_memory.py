"""Instances release what they take (issue 21): 200 instances, memory flat.

Each instance unpacked into its own folder used to leave about 353 KiB mapped after
terminate, free and removal of the folder: a copy of the front (49 KiB) and of pythonfmu's
binary (276 KiB) per folder, never unloaded, and a new class of the slave per instance
(12 KiB, pythonfmu's findClass). Now the first copy of the front owns pythonfmu's binary
and later copies share it and can be unloaded (front/backend.c, share.c); the slave
module pythonfmu runs again per instance only imports its class (front.stage_slave_module);
the front takes pythonfmu's sys.path entry off again.

The stated bound, after 400 warm-up instances, over 600 more: no more mappings of FMU
binaries, no more sys.path entries, at most 1.5 Python objects per instance, and at most
8 KiB of resident memory per instance in the median of three blocks of 200 (before: 353 KiB).
A leak grows every block; the median leaves out a one-off step. Measured now (this probe,
by hand, the plant): 2.9, 4.2 and 4.2 KiB in the three blocks, twice; over 400 instances in
one block it gave 3.7 KiB by hand and 5.2 KiB once in CI, over the 5 KiB bound this test
had. 8 KiB still fails on the smallest of the leaks above (a class per instance, 12 KiB). The first instances take
more each, once: the allocators' pools, the front's table of freed instances, and Python's
table of interned strings, which pathlib fills with each instance's folder name and which
grew once by 939 KiB between the 200th and the 400th instance (tracemalloc); a 200-instance
warm-up, which this test had, caught that growth in its measurement (5.1-7.7 KiB per
instance). After it, the Python-level growth is 1.05-1.26 KiB per instance (tracemalloc,
blocks of 200 up to 1,200 instances), nearly all of it made in fmi2Instantiate. What is left is pythonfmu 0.7.0's: one
object per instance, the list of the slave class's bases that findClass never frees, with
their names.
Run by hand: ``python tests/support/instance_memory_probe.py FMU --warm 400 --instances 600 --blocks 3``.
"""
import json
import subprocess
import sys
from pathlib import Path

import pytest

PROBE = Path(__file__).parents[1] / "support" / "instance_memory_probe.py"
KIB_PER_INSTANCE = 8.0   # median of the blocks; below the 12-KiB class-per-instance leak
OBJECTS_PER_INSTANCE = 1.5


def _probe(fmu, *options):
    result = subprocess.run([sys.executable, str(PROBE), str(fmu), *options], capture_output=True,
                            text=True, timeout=600)
    assert result.returncode == 0, result.stderr[-3000:]
    return json.loads(result.stdout.strip().splitlines()[-1])


@pytest.mark.parametrize("name", ["SmaActuator", "SmaFeedforward"])
def test_200_instances_leave_memory_flat(fmus, name):
    report = _probe(fmus[name], "--warm", "400", "--instances", "600", "--blocks", "3")
    growth = report["growth"]
    assert report["before"]["binary_mappings"] > 0  # the owner's front and pythonfmu's binary
    assert growth["binary_mappings"] == 0, report
    assert growth["sys_path"] == 0 and growth["importer_cache"] <= 0, report
    assert report["objects_per_instance"] <= OBJECTS_PER_INSTANCE, report
    assert report["rss_kib_per_instance_median"] <= KIB_PER_INSTANCE, report


def test_plain_fmpy_adds_no_sys_path_entry_and_no_mapping(fmus):
    report = _probe(fmus["SmaActuator"], "--warm", "10", "--instances", "40", "--fmpy")
    assert report["growth"]["sys_path"] == 0, report
    assert report["growth"]["binary_mappings"] == 0, report
