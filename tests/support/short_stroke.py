"""The shipped 0.5 Hz stroke profile on the Flexinol fit, shortened for tests: a derived
scenario file in a test's folder (the shipped one takes 30 s and maps 30,001 steps)."""
from sma_fmu.cosim.scenario import load_scenario
from sma_fmu.files.package_data import shipped_file

PROFILE = "flexinol-stroke-profile-pi+ff-adaptive"


def short_profile(folder, stop_time_s=4.0, T_start_degC=None):
    """The profile for ``stop_time_s`` [s] (default 4 s), the loads stepping at 1.5 and 3 s (a
    turn of the reference in each load), metrics from 0.5 s, written into ``folder``; with
    ``T_start_degC`` the wire starts there instead of at T_room (10 degC, below the fit's
    data). Returns the loaded scenario (its ``path`` is the file)."""
    text = shipped_file("scenarios", f"{PROFILE}.toml").read_text()
    models = shipped_file("models", "flexinol_fit.toml").parent
    text = (text.replace('model = "../models/', f'model = "{models}/')
            .replace("stop_time_s = 30.0", f"stop_time_s = {stop_time_s!r}")
            .replace("times_s = [0.0, 10.0, 20.0]", "times_s = [0.0, 1.5, 3.0]"))
    if T_start_degC is not None:
        text = text.replace('hysteresis_mode = "continuous"',
                            f'hysteresis_mode = "continuous"\nT_start_degC = {T_start_degC!r}')
    path = folder / "stroke-profile-short.toml"
    path.write_text(text + "\n[analysis]\nmetrics_start_s = 0.5\n")
    return load_scenario(path)
