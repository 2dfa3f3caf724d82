"""Close the loop around the sma-fmu FMUs with your own PI controller, in plain fmpy.

    sma-fmu build --out fmus                     # SmaActuator.fmu, SmaFeedforward.fmu
    python fmpy_closed_loop.py fmus [--stop 30] [--load 0.25] [--mode continuous]

The plant (SmaActuator) and the compensator (SmaFeedforward) are driven through fmpy's
FMU2Slave. The PI controller is written here, in ten lines: yours would replace it. Per
step (Gauss-Seidel, the compensator before the plant, as in sma-fmu's own master):
read R; e = R - R_ref; the compensator gives P_ff for R_ref and the load; the PI adds
Kp e + Ki I and clamps the sum at 0 W; the plant steps with that power and the load held.
The reference is the paper's R_ref(t) = 41.85 + 6.05 cos(pi t) ohm. Prints the RMSE of
R - R_ref over t >= 2 s, and writes a CSV of the run if --csv is given.
"""
import argparse
import csv
import math
import shutil
from pathlib import Path

from fmpy import extract, read_model_description
from fmpy.fmi2 import FMU2Slave

# SmaActuator's Integer parameter hysteresis_mode: the code of each mode
HYSTERESIS_MODES = {"continuous": 1, "switch": 2}


def open_fmu(path, instance_name, reals=None, integers=None, booleans=None):
    """Instantiate an FMU, set start values in initialization mode, and return (fmu, refs)."""
    description = read_model_description(str(path))
    refs = {v.name: v.valueReference for v in description.modelVariables}
    folder = extract(str(path))
    fmu = FMU2Slave(guid=description.guid, unzipDirectory=folder,
                    modelIdentifier=description.coSimulation.modelIdentifier,
                    instanceName=instance_name)
    fmu.instantiate()
    fmu.setupExperiment(startTime=0.0)
    fmu.enterInitializationMode()
    for setter, values in ((fmu.setReal, reals), (fmu.setInteger, integers),
                           (fmu.setBoolean, booleans)):
        if values:
            setter([refs[name] for name in values], list(values.values()))
    fmu.exitInitializationMode()
    return fmu, refs, folder


def reference(t):
    """The paper's reference resistance [ohm] at time t [s]."""
    return 41.85 + 6.05 * math.cos(2.0 * math.pi * 0.5 * t)


def run(fmu_dir, stop=30.0, step=1e-3, load=0.25, mode="continuous", Kp=0.3, Ki=1.0):
    """Run the loop; returns rows (t, R_ref, R, T, P_ff, P) with one row per sample."""
    plant, p, plant_folder = open_fmu(Path(fmu_dir) / "SmaActuator.fmu", "plant",
                                      reals={"load": load},
                                      integers={"hysteresis_mode": HYSTERESIS_MODES[mode]})
    ff, f, ff_folder = open_fmu(Path(fmu_dir) / "SmaFeedforward.fmu", "feedforward",
                                reals={"R_ref": reference(0.0), "load": load})
    rows, integral = [], 0.0
    try:
        R, T = plant.getReal([p["R"], p["T"]])
        for k in range(int(round(stop / step))):
            t = k * step
            r_ref = reference(t)
            error = R - r_ref
            ff.setReal([f["R_ref"], f["load"]], [r_ref, load])
            ff.doStep(t, step)
            p_ff, = ff.getReal([f["P_ff"]])
            # --- your controller: PI with the power clamped at 0 W and no wind-up below it ---
            raw = p_ff + Kp * error + Ki * integral
            power = max(0.0, raw)
            if raw >= 0.0 or error > 0.0:
                integral += step * error
            # ----------------------------------------------------------------------------
            rows.append((t, r_ref, R, T, p_ff, power))
            plant.setReal([p["P_in"], p["load"]], [power, load])
            plant.doStep(t, step)
            R, T = plant.getReal([p["R"], p["T"]])
        rows.append((stop, reference(stop), R, T, math.nan, math.nan))
    finally:
        for fmu, folder in ((plant, plant_folder), (ff, ff_folder)):
            fmu.terminate()
            fmu.freeInstance()
            shutil.rmtree(folder, ignore_errors=True)
    return rows


def rmse(rows, start=2.0):
    """RMSE of R - R_ref [ohm] over the samples with t >= start [s]."""
    errors = [R - r_ref for t, r_ref, R, *_ in rows if t >= start - 1e-9]
    return math.sqrt(sum(e * e for e in errors) / len(errors))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("fmus", help="folder with SmaActuator.fmu and SmaFeedforward.fmu")
    parser.add_argument("--stop", type=float, default=30.0, help="duration [s] (30)")
    parser.add_argument("--load", type=float, default=0.25, help="hung mass [kg] (0.25)")
    parser.add_argument("--mode", default="continuous", choices=sorted(HYSTERESIS_MODES),
                        help="hysteresis mode (continuous)")
    parser.add_argument("--csv", help="write the run to this CSV file")
    args = parser.parse_args()
    rows = run(args.fmus, args.stop, load=args.load, mode=args.mode)
    if args.csv:
        with open(args.csv, "w", newline="") as stream:
            writer = csv.writer(stream)
            writer.writerow(["t_s", "R_ref_ohm", "R_ohm", "T_degC", "P_ff_W", "P_W"])
            writer.writerows(rows)
    print(f"RMSE over t >= 2 s: {rmse(rows):.6f} ohm")


if __name__ == "__main__":
    main()
