"""The PWM table of issue 17 on the library plant: the same mean power as constant power, 500 Hz
and 50 Hz PWM (peak = 2 x mean), R [ohm] over the last 5 s of a 60-s run, load 0.05 kg.

Run: python benchmarks/pwm_table.py  (prints Markdown rows; about 10 s)
"""
from sma_fmu.wire.parameter_file import load_parameters
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.pwm import PwmDriver
p = load_parameters(); load = 0.05; h = 1e-3
def run(mode, T_mean, drive, seconds=60.0):
    P = (T_mean - p.T_room) / p.K_th
    plant = PlantStepper(p, mode=mode, load=load)
    pwm = None if drive is None else PwmDriver(drive, 2.0 * P)
    Rs = []
    for k in range(int(seconds / h)):
        u = P if pwm is None else pwm.step(P, k * h, h)
        out = plant.step(u, load, h)
        if k * h >= seconds - 5.0: Rs.append(out.R)
    return min(Rs), max(Rs)
for T in (60.0, 68.0, 75.0):
    for mode in ("switch", "continuous"):
        cells = []
        for drive in (None, 500.0, 50.0):
            lo, hi = run(mode, T, drive)
            cells.append(f"{lo:.2f}" if hi - lo < 0.01 else f"{lo:.2f} … {hi:.2f}")
        print(f"| {T:.0f} °C | {mode} | " + " | ".join(cells) + " |")
