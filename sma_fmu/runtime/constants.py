"""Physical constants and conventions shared by every model (SI, CODATA 2018 exact values)."""

__all__ = [
    "AVOGADRO", "BOLTZMANN", "MOLAR_MASS_TI", "MOLAR_MASS_NI", "STANDARD_GRAVITY",
    "KELVIN_OFFSET", "HEATING", "COOLING",
]

AVOGADRO = 6.02214076e23        # 1/mol
BOLTZMANN = 1.380649e-23        # J/K
MOLAR_MASS_TI = 47.867e-3       # kg/mol
MOLAR_MASS_NI = 58.6934e-3      # kg/mol
STANDARD_GRAVITY = 9.80665      # m/s^2: a hung mass f [kg] pulls with g*f [N]
KELVIN_OFFSET = 273.15          # K: T_K = T_degC + KELVIN_OFFSET

HEATING = 1                     # direction d = sgn(dT/dt) while heating
COOLING = -1                    # direction d while cooling
