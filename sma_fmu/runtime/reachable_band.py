"""The resistance band a wire can reach under a load: (R_hot(f), R_cold(f)) (spec sections 4-5).

    R_hot(f)  = R_P + xi_Fmin(f) (R_F - R_P)           all transformable lattice in P (xi_MF = 0)
    R_cold(f) = R_hot(f) + M(f) (R_MF - R_P)            all of it in M and F (xi_MF = M)

The resistance of a wire under load f lies strictly inside this band, whatever its
temperature, direction or history: the logistic branches of section 4 and the minor
branches of section 6 only approach the ends. A reference outside the band cannot be
tracked by any controller at that load. Neither end depends on the direction. This is
the one place the band is computed: the temperature-sensing inverse, the compensator,
the co-simulation metrics and the tracking bound all use it.
"""
from collections import namedtuple

from .constant_load import branch_constants
from .constants import HEATING

__all__ = ["ResistanceBand", "band_of_branch", "reachable_band"]

ResistanceBand = namedtuple("ResistanceBand", ["hot", "cold"])
ResistanceBand.__doc__ = """The reachable resistances at one load.

hot : R_hot(f), the fully heated end (lowest resistance) [ohm];
cold : R_cold(f), the fully cooled end (highest resistance) [ohm].
"""


def band_of_branch(constants, params):
    """(R_hot, R_cold) [ohm] of a branch with :class:`~.constant_load.BranchConstants`.

    No argument checks: this is on the compensator's hot path.
    """
    hot = params.R_P + constants.xi_F_min * (params.R_F - params.R_P)
    return hot, hot + constants.M * (params.R_MF - params.R_P)


def reachable_band(load, params):
    """:class:`ResistanceBand` [ohm] under ``load`` [kg] (raises ``ValueError`` on a bad load)."""
    hot, cold = band_of_branch(branch_constants(load, HEATING, params), params)
    return ResistanceBand(hot, cold)
