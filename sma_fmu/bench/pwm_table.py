"""The PWM table of docs/model.md §6 on the library plant: ``sma-fmu bench --only pwm``.

The same mean power as constant power, 500 Hz and 50 Hz PWM (peak = 2 x mean): R [ohm] over
the last 5 s of a 60-s run at load 0.05 kg and h = 1 ms, per mean temperature and
hysteresis mode. A cell is one number when R holds still (spread below 0.01 ohm), else
"min ... max". About 10 s.
"""
from sma_fmu.runtime.plant import PlantStepper
from sma_fmu.runtime.pwm import PwmDriver
from sma_fmu.wire.parameter_file import load_parameters

__all__ = ["PWM_LOAD_KG", "pwm_cell", "pwm_table_rows"]

PWM_LOAD_KG = 0.05
_STEP_S = 1e-3


def pwm_cell(params, mode, T_mean, frequency_Hz, seconds=60.0):
    """(min, max) of R [ohm] over the last 5 s with the power of ``T_mean`` [degC] held, as
    constant power (``frequency_Hz`` None) or as PWM at ``frequency_Hz`` [Hz]."""
    power = (T_mean - params.T_room) / params.K_th
    plant = PlantStepper(params, mode=mode, load=PWM_LOAD_KG)
    pwm = None if frequency_Hz is None else PwmDriver(frequency_Hz, 2.0 * power)
    resistances = []
    for k in range(int(seconds / _STEP_S)):
        applied = power if pwm is None else pwm.step(power, k * _STEP_S, _STEP_S)
        out = plant.step(applied, PWM_LOAD_KG, _STEP_S)
        if k * _STEP_S >= seconds - 5.0:
            resistances.append(out.R)
    return min(resistances), max(resistances)


def pwm_table_rows(params=None, temperatures=(60.0, 68.0, 75.0), say=print):
    """Print and return the Markdown rows: mean T | mode | constant | 500 Hz | 50 Hz."""
    params = load_parameters() if params is None else params
    rows = []
    for T_mean in temperatures:
        for mode in ("switch", "continuous"):
            cells = []
            for frequency in (None, 500.0, 50.0):
                low, high = pwm_cell(params, mode, T_mean, frequency)
                cells.append(f"{low:.2f}" if high - low < 0.01 else f"{low:.2f} … {high:.2f}")
            rows.append(f"| {T_mean:.0f} °C | {mode} | " + " | ".join(cells) + " |")
            say(rows[-1])
    return rows
