"""Minor loops with return-point memory: hysteresis mode "continuous" (spec section 6).

The wire remembers a stack of reversal points (T_i [degC], xi_i [1]), alternately maxima
and minima of the temperature, the oldest first. With the stack empty it is on the major
branch of its direction, xi_MF = L_d(T). Otherwise it is on the branch that leaves the top
point A towards B, the point below it (or the end of the major loop: heating T -> +inf,
xi_MF -> 0; cooling T -> -inf, xi_MF -> M):

    heating:  xi_MF(T) = xi_B + (xi_A - xi_B) (L_h(T) - L_h(T_B)) / (L_h(T_A) - L_h(T_B))
    cooling:  p(T)     = p_B  + (p_A - p_B)   (P_c(T) - P_c(T_B)) / (P_c(T_A) - P_c(T_B)),
              p = M - xi_MF, P_c = M - L_c (so neither end of the transformation loses digits)

A reversal pushes the state before its step; a loop that closes (the temperature reaches
or passes T_B) is wiped out: A and B are popped and the wire goes on along the outer
branch, which passes through B. So a minor loop closes exactly where it began (return-point
memory). A branch whose denominator is below :data:`DENOMINATOR_FLOOR` is flat (it stays
at A until wiped out); values are clamped into [0, M]. At most ``depth`` points are kept:
a push beyond that drops the two oldest.

Every function works in "branch values" v: xi_MF when heating, p = M - xi_MF when cooling,
and L_d is the major branch's matching value (its xi_MF heating, its xi_P cooling). Both
fall as the wire moves along its direction, so heating and cooling share one code path.
"""
from collections import namedtuple

from .constants import HEATING
from .constant_load import branch_fractions

__all__ = ["ReversalPoint", "Branch", "DENOMINATOR_FLOOR", "DEFAULT_DEPTH", "push_reversal",
           "wipe_out", "branch_of", "fractions_on_branch", "fractions_on_stack",
           "major_value", "value_of", "fractions_of_value", "read_points"]

DENOMINATOR_FLOOR = 1e-12
DEFAULT_DEPTH = 64

ReversalPoint = namedtuple("ReversalPoint", ["temperature", "xi_MF"])
ReversalPoint.__doc__ = ("A reversal: the state before the step in which the direction changed, "
                         "T [degC] and xi_MF [1].")

Branch = namedtuple("Branch", ["value_B", "ratio", "major_B"])
Branch.__doc__ = """The branch leaving the top of the stack, as an affine map of the major branch.

v(T) = value_B + ratio (L_d(T) - major_B), clamped into [0, M]; v is xi_MF heating, M - xi_MF
cooling. A flat branch has ratio 0 and value_B = v_A.
"""


def push_reversal(points, temperature, xi_mf, depth):
    """Push the reversal (``temperature`` [degC], ``xi_mf`` [1]) onto ``points`` (a list).

    When the stack would hold more than ``depth`` points the two oldest are dropped.
    """
    points.append(ReversalPoint(temperature, xi_mf))
    if len(points) > depth:
        del points[:2]


def wipe_out(points, temperature, direction):
    """Pop closed loops: while two points or more are stored and ``temperature`` [degC] has
    reached or passed T_B in ``direction``, drop A and B. Returns the number of points dropped."""
    dropped = 0
    heating = direction == HEATING
    while len(points) >= 2:
        bound = points[-2].temperature
        if (temperature >= bound) if heating else (temperature <= bound):
            del points[-2:]
            dropped += 2
        else:
            break
    return dropped


def major_value(temperature, constants, heating):
    """L_d(T): the major branch's xi_MF when heating, its xi_P when cooling [1]."""
    return branch_fractions(temperature, constants)[0 if heating else 1]


def value_of(point, total, heating):
    """The branch value of a stored point: xi_MF heating, M - xi_MF cooling [1]."""
    return point.xi_MF if heating else total - point.xi_MF


def fractions_of_value(value, total, heating):
    """(xi_MF, xi_P) [1] of a branch value ``value`` [1] in the direction ``heating``."""
    return (value, total - value) if heating else (total - value, value)


def branch_of(points, count, constants, direction):
    """The :class:`Branch` leaving ``points[count - 1]`` (``count`` >= 1) at the present load.

    ``constants`` are the :class:`~.constant_load.BranchConstants` of the major branch of
    ``direction``; the stored points keep their (T, xi_MF) across load changes.
    """
    heating = direction == HEATING
    total = constants.M
    top = points[count - 1]
    value_A = value_of(top, total, heating)
    major_A = major_value(top.temperature, constants, heating)
    if count >= 2:
        below = points[count - 2]
        value_B = value_of(below, total, heating)
        major_B = major_value(below.temperature, constants, heating)
    else:  # the end of the major loop
        value_B = major_B = 0.0
    denominator = major_A - major_B
    if abs(denominator) < DENOMINATOR_FLOOR:
        return Branch(value_A, 0.0, 0.0)
    return Branch(value_B, (value_A - value_B) / denominator, major_B)


def fractions_on_branch(temperature, constants, direction, branch):
    """(xi_MF, xi_P) [1] at ``temperature`` [degC] on ``branch`` (None: the major branch)."""
    fractions = branch_fractions(temperature, constants)
    if branch is None:
        return fractions
    heating = direction == HEATING
    total = constants.M
    value = branch.value_B + branch.ratio * (fractions[0 if heating else 1] - branch.major_B)
    value = 0.0 if value < 0.0 else (total if value > total else value)
    return fractions_of_value(value, total, heating)


def fractions_on_stack(temperature, constants, direction, points, count=None):
    """(xi_MF, xi_P) [1] at ``temperature`` on the branch of the stack ``points[:count]``."""
    count = len(points) if count is None else count
    branch = branch_of(points, count, constants, direction) if count else None
    return fractions_on_branch(temperature, constants, direction, branch)


def read_points(value, depth, name="reversals"):
    """Validate a saved stack (a list of [T degC, xi_MF 1] pairs); returns a list of points.

    Raises ``ValueError`` naming ``name`` when it is not a list of at most ``depth`` pairs
    of finite numbers with T above absolute zero and xi_MF in [0, 1].
    """
    if not isinstance(value, (list, tuple)) or len(value) > depth:
        raise ValueError(f"{name} must be a list of at most {depth} [T, xi_MF] pairs, "
                         f"got {value!r:.200}")
    points = []
    for index, pair in enumerate(value):
        if (not isinstance(pair, (list, tuple)) or len(pair) != 2
                or not all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in pair)):
            raise ValueError(f"{name}[{index}] must be a [T, xi_MF] pair of numbers, got {pair!r:.200}")
        temperature, xi_mf = float(pair[0]), float(pair[1])
        if not (-273.15 < temperature < float("inf") and 0.0 <= xi_mf <= 1.0):
            raise ValueError(f"{name}[{index}] = {pair!r}: T must be finite above -273.15 degC "
                             "and xi_MF in [0, 1]")
        points.append(ReversalPoint(temperature, xi_mf))
    return points
