"""Work with results in plain Python: runs as DataFrames, metrics as records, a figure.

    python results_api.py [--stop 30] [--out DIR]

1. Runs the three controllers of the paper's load-step profile (continuous hysteresis)
   in one batch through the study API; their metrics become one pandas table, ranked.
2. Takes the best run's time series (a DataFrame with the CSV's columns and units) and
   reports, per load segment, the stroke the wire gave and the power it took.
3. Writes that run the way ``sma-fmu run`` does (timeseries.csv, metrics.json) and reads
   it back with pandas and json, as a user's own scripts read ``sma-fmu run``'s results.
4. Saves a figure of resistance and stroke (matplotlib Figure, no screen needed).
"""
import argparse
import json
import tempfile
from pathlib import Path

import pandas as pd
from matplotlib.figure import Figure

from sma_fmu.files.json_output import json_text
from sma_fmu.studies import run_many, scenario

CONTROLLERS = ("pi", "pi+ff-fixed", "pi+ff-adaptive")


def ranked_runs(stop):
    """The three controllers on load-step (continuous), ``stop`` [s] long: (runs, ranking table)."""
    items = [scenario(f"load-step-continuous-{kind}", {"scenario.stop_time_s": stop})
             for kind in CONTROLLERS]
    runs = run_many(items, path="batch")
    table = pd.DataFrame([r.record() for r in runs]).sort_values("rmse_ohm")
    return runs, table[["scenario", "controller", "rmse_ohm", "max_abs_ohm", "iae_ohm_s"]]


def per_segment(frame):
    """Stroke [mm] and mean power [W] per load of a time-series DataFrame."""
    window = frame[frame["t_s"] >= 2.0]
    groups = window.groupby("load_kg")
    return pd.DataFrame({
        "stroke_min_mm": 1e3 * groups["stroke_m"].min(),
        "stroke_max_mm": 1e3 * groups["stroke_m"].max(),
        "mean_power_W": groups["P_W"].mean(),
        "rmse_ohm": groups.apply(lambda g: ((g["R_ohm"] - g["R_ref_ohm"]) ** 2).mean() ** 0.5,
                                 include_groups=False),
    })


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--stop", type=float, default=30.0, help="run length [s] (30)")
    parser.add_argument("--out", help="results folder (default: a temporary one)")
    args = parser.parse_args()
    out = Path(args.out or tempfile.mkdtemp())

    runs, table = ranked_runs(args.stop)
    print("ranking (RMSE of R - R_ref over the metrics window):")
    print(table.to_string(index=False, float_format=lambda v: f"{v:.4f}"))

    best = next(r for r in runs if r.scenario.name == table.iloc[0]["scenario"])
    print(f"\n{best.scenario.name} per load segment (t >= 2 s):")
    print(per_segment(best.timeseries).to_string(float_format=lambda v: f"{v:.3f}"))

    written = out / best.scenario.name
    written.mkdir(parents=True, exist_ok=True)
    best.timeseries.to_csv(written / "timeseries.csv", index=False)
    (written / "metrics.json").write_text(json_text(best.metrics), encoding="utf-8")
    frame = pd.read_csv(written / "timeseries.csv")
    metrics = json.loads((written / "metrics.json").read_text())
    print(f"\nread back {written}: {len(frame)} rows, columns {', '.join(frame.columns[:6])}, ...; "
          f"RMSE {metrics['overall']['rmse_ohm']:.4f} ohm")

    figure = Figure(figsize=(9, 5))
    top, bottom = figure.subplots(2, 1, sharex=True)
    data = best.timeseries
    top.plot(data["t_s"], data["R_ref_ohm"], "k--", lw=0.8, label="R_ref")
    top.plot(data["t_s"], data["R_ohm"], lw=0.8, label="R")
    bottom.plot(data["t_s"], 1e3 * data["stroke_m"], color="tab:green", lw=0.8, label="stroke")
    top.set_ylabel("resistance [ohm]")
    bottom.set(xlabel="time t [s]", ylabel="stroke [mm]")
    for axis in (top, bottom):
        axis.legend(loc="upper right")
        axis.grid(alpha=0.3)
    figure.tight_layout()
    figure.savefig(out / "best.png", dpi=100)
    print(f"figure: {out / 'best.png'}")


if __name__ == "__main__":
    main()
