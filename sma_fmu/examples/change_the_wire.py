"""Change the wire and rerun a scenario through the library: a shorter wire, from its geometry.

    python change_the_wire.py [--length 0.5] [--out DIR]

A user cuts the reference wire (0.15 mm, 0.800 m) to another length. What changes:
- the lengths x0, x_min, l_M, l_F scale with it, and so do the phase resistances R_P, R_M,
  R_F (a wire's resistance is proportional to its length);
- the surface A_s and the mass follow from diameter, length and density: the parameter
  file leaves them out and the loader derives them (``sma-fmu wire`` says so);
- the reference must scale too: 41.85 +- 6.05 ohm is out of reach of a shorter wire.
Then the paper's load-step scenario (continuous hysteresis, PI + adaptive feedforward)
runs for both wires through the study API, plant and compensator both on the new wire.
Prints the derived values and both runs' thermal constants and RMSE.
"""
import argparse
import tempfile
from pathlib import Path

from sma_fmu.files.package_data import shipped_file
from sma_fmu.wire.parameter_file import load_parameter_set
from sma_fmu.studies import run

NITI_DENSITY = 6450.0  # kg/m3
SCALED_BY_LENGTH = ("x0", "x_min", "l_M", "l_F", "R_P", "R_M", "R_F")


def cut_wire_file(length, folder):
    """A parameter file of the reference wire cut to ``length`` [m]; A_s and mass left out."""
    reference = load_parameter_set()
    share = length / reference.params.x0
    lines = []
    for line in shipped_file("models", "reference_wire.toml").read_text().splitlines():
        key = line.split("=")[0].strip()
        if key in ("A_s", "mass"):
            continue                       # derived from the geometry instead
        if key in SCALED_BY_LENGTH:
            value = getattr(reference.params, key) * share
            start = line.index("value = ") + len("value = ")
            line = f"{line[:start]}{value!r}{line[line.index(',', start):]}"
        lines.append(line)
        if line.strip() == "[geometry]":
            lines.append(f'density = {{ value = {NITI_DENSITY}, unit = "kg/m3", '
                         f'meaning = "NiTi density" }}')
    path = Path(folder) / f"wire_{length:g}m.toml"
    path.write_text("\n".join(lines) + "\n", encoding="utf-8")
    return path, share


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--length", type=float, default=0.5, help="new wire length [m] (0.5)")
    parser.add_argument("--out", help="folder for the new parameter file (default: a temporary one)")
    args = parser.parse_args()
    folder = args.out or tempfile.mkdtemp()
    path, share = cut_wire_file(args.length, folder)
    wire = load_parameter_set(path)
    print(f"new parameter file: {path}")
    for name, how in wire.derived.items():
        print(f"  derived {name}: {how}")
    base = "load-step-continuous-pi+ff-adaptive"
    runs = {
        "reference wire": run(base),
        f"{args.length:g} m wire": run(base, {
            "scenario.model": str(path),                      # plant and compensator: the new wire
            "reference.offset_ohm": 41.85 * share,            # the reference scales with R
            "reference.amplitude_ohm": 6.05 * share,
        }),
    }
    print(f"{'run':<18}{'K_th [K/W]':>12}{'tau_th [s]':>12}{'RMSE [ohm]':>12}{'RMSE/R_ref':>12}"
          f"{'mean P [W]':>12}")
    for label, result in runs.items():
        params = result.scenario.params
        rmse = result.metrics["overall"]["rmse_ohm"]
        offset = result.scenario.reference.settings["offset_ohm"]
        power = result.timeseries["P_W"].iloc[:-1].mean()
        print(f"{label:<18}{params.K_th:>12.4f}{params.tau_th:>12.4f}{rmse:>12.4f}"
              f"{rmse / offset:>12.4%}{power:>12.4f}")


if __name__ == "__main__":
    main()
