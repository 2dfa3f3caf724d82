"""What instances leave behind: make N instances of an FMU, each unpacked into its own folder
(as fmpy's simulate_fmu does, and FmuInstance with SMA_FMU_UNPACK_EACH=1, which this probe
sets unless ``--shared``), and measure the process before and after.

    python tests/support/instance_memory_probe.py FMU [--warm 50] [--instances 200] [--blocks 1]
        [--fmpy] [--shared]

Prints one JSON object: resident memory growth per instance [KiB], growth of the mappings
of FMU binaries, of sys.path, of sys.path_importer_cache and of Python objects. With
``--blocks N`` the measured instances run in N equal blocks and the resident growth per
instance of each block is reported too, with their median: a leak grows every block, a
one-off step (an allocator's pool, a hash table doubling) only one. ``--fmpy``
uses plain ``fmpy.simulate_fmu`` instead of :class:`~sma_fmu.fmi.driving.instance.FmuInstance`.
Each instance is initialized, stepped, terminated and freed, and its folder removed.
"""
import argparse
import gc
import json
import os
import re
import statistics
import sys


def _state():
    status = open("/proc/self/status").read()
    binaries = [line for line in open("/proc/self/maps") if "/binaries/" in line]
    return {"rss_kib": int(re.search(r"VmRSS:\s+(\d+)", status).group(1)),
            "binary_mappings": len(binaries), "sys_path": len(sys.path),
            "importer_cache": len(sys.path_importer_cache), "objects": len(gc.get_objects())}


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("fmu")
    parser.add_argument("--warm", type=int, default=50, help="instances before the first measurement")
    parser.add_argument("--instances", type=int, default=200, help="instances measured")
    parser.add_argument("--blocks", type=int, default=1, help="blocks the measured instances run in")
    parser.add_argument("--fmpy", action="store_true", help="plain fmpy.simulate_fmu")
    parser.add_argument("--shared", action="store_true",
                        help="FmuInstance's instances share one unpacked folder (its default)")
    args = parser.parse_args(argv)
    if not args.shared:
        os.environ["SMA_FMU_UNPACK_EACH"] = "1"  # a folder per instance, as the docstring says
    if args.fmpy:
        from fmpy import simulate_fmu

        def one(k):
            simulate_fmu(args.fmu, stop_time=0.002, step_size=0.001, start_values={"load": 0.05})
    else:
        from sma_fmu.fmi.driving.instance import FmuInstance

        def one(k):
            with FmuInstance(args.fmu, f"probe{k}", {"load": 0.05}) as fmu:
                fmu.step(0.0, 1e-3)

    for k in range(args.warm):
        one(k)
    gc.collect()
    before = _state()
    size = args.instances // args.blocks
    blocks, last = [], before
    for block in range(args.blocks):
        for k in range(block * size, (block + 1) * size):
            one(k)
        gc.collect()
        state = _state()
        blocks.append(round((state["rss_kib"] - last["rss_kib"]) / size, 2))
        last = state
    after = last
    growth = {key: after[key] - before[key] for key in before}
    measured = size * args.blocks
    print(json.dumps({"instances": measured, "before": before, "after": after,
                      "rss_kib_per_instance": round(growth["rss_kib"] / measured, 2),
                      "rss_kib_per_instance_blocks": blocks,
                      "rss_kib_per_instance_median": statistics.median(blocks),
                      "objects_per_instance": round(growth["objects"] / measured, 2),
                      "growth": growth}))


if __name__ == "__main__":
    main()
