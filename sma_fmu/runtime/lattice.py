"""Crystal-lattice constants of the wire from its geometry (spec section 1, paper Table 1)."""
import math
from collections import namedtuple

from .constants import AVOGADRO, MOLAR_MASS_NI, MOLAR_MASS_TI

__all__ = ["Lattice", "lattice_constants"]

Lattice = namedtuple("Lattice", ["N", "x_P", "N_l", "N_S"])
Lattice.__doc__ = """Lattice constants.

N : number of unit cells [1] (half the atoms: two atoms per P cell)
x_P : edge of the cubic P cell [m]
N_l : cells along the wire [1]
N_S : cells across the wire section [1]
"""


def lattice_constants(x0, x_min, diameter, theta, line_density):
    """Lattice constants of a wire.

    Parameters
    ----------
    x0 : float
        Length at low temperature, never loaded [m].
    x_min : float
        Length when fully P phase [m].
    diameter : float
        Wire diameter [m].
    theta : float
        Atomic fraction of Ti [1].
    line_density : float
        Mass per unit length [kg/m].
    """
    mean_molar_mass = theta * MOLAR_MASS_TI + (1.0 - theta) * MOLAR_MASS_NI
    n_cells = AVOGADRO * x0 * line_density / (2.0 * mean_molar_mass)
    x_p = (math.pi * diameter ** 2 * x_min / (4.0 * n_cells)) ** (1.0 / 3.0)
    n_l = x_min / x_p
    return Lattice(N=n_cells, x_P=x_p, N_l=n_l, N_S=n_cells / n_l)
