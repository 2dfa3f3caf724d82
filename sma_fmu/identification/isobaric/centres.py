"""How the isobaric fit holds the hysteresis centres of one transformation stage.

The model's centres are straight lines in the load, tau_d(f) = a_d + b_d f [degC, degC/kg]
for heating (d = h) and cooling (d = c). The fit does not hold a_h, b_h, a_c, b_c
directly, for two reasons:

- **One load cannot tell a slope.** With one load (or one stress) the data fix the two
  centres at that load, tau_h(f) and tau_c(f), and nothing else. So these two are the
  unknowns (``tau_c`` and the heating centre's lead ``gap`` >= 0 over it), and the slopes
  are kept out of the cost: the fitted curve is the same whatever load the file is said to
  hold; only a_d = tau_d(f) - b_d f moves with it. The slopes written to the wire file are
  the base file's, unless those put the heating centre below the cooling one somewhere
  between no load and the fitted load (the reference wire's 100 and 60 degC/kg need a
  hysteresis of 40 K at 1 kg); then both take their mean, so the hysteresis fitted at the
  load holds at every load. :attr:`LinearCentres.slope_note` says which.
- **Heating at or above cooling where the data are.** With several loads the cooling line is
  held by its centres at the lowest and the highest load (``tau_c_lo``, ``tau_c_hi``) and
  the heating centre's lead over it at the same two loads (``gap_lo``, ``gap_hi`` >= 0):
  it is then >= 0 at every load in between, not at zero load, which the data may not
  reach. The second stage holds its lead at no load and the highest load instead, because
  the wire-file contract requires a2_h >= a2_c.
- **Inside the data.** Each cooling centre is bounded by the measured temperature range
  and each lead by its span: a stage centred outside the data would not be a transformation
  but a bend in a baseline (on the NiTiHf set a second stage ran to 400 degC and a domain
  size of 6 without this).

Another centre law (say, one following Clausius-Clapeyron) plugs in as a class with the
same members: ``names``, ``start``, ``bounds``, ``parameters`` (wire-file names from the
unknowns, linear in them) and ``settle`` (choices made after the fit), and a vectorised
centre in :mod:`~.terms`.
"""
__all__ = ["LinearCentres"]


# [degC] the centres' bounds when no measured range is given
DEFAULT_TEMPERATURES = (-100.0, 400.0)


class LinearCentres:
    """The centres of one stage (1 or 2) as unknowns, for the distinct ``loads`` [kg] of
    the files; ``base`` gives the slopes when one load cannot; ``temperatures`` = (lowest,
    highest) measured temperature [degC] bounds the centres."""

    def __init__(self, loads, base, stage=1, temperatures=DEFAULT_TEMPERATURES):
        loads = sorted({float(f) for f in loads})
        self.stage = stage
        self.prefix = "" if stage == 1 else "2"
        self.load = loads[0] if loads else 0.0
        self.temperatures = (float(temperatures[0]), float(temperatures[1]))
        self.fit_slopes = len(loads) >= 2 and loads[-1] > loads[0]
        terms = base.terms
        self.base_slopes = (base.b_h, base.b_c) if stage == 1 else (terms.b2_h, terms.b2_c)
        self.slopes = self.base_slopes
        self.slope_note = ""
        s = self.prefix
        if self.fit_slopes:
            self.anchors = (loads[0], loads[-1])                       # of the cooling line
            self.gap_anchors = (loads[0] if stage == 1 else 0.0, loads[-1])
            self.names = [f"tau{s}_c_lo", f"tau{s}_c_hi",
                          f"gap{s}_" + ("lo" if stage == 1 else "0"), f"gap{s}_hi"]
        else:
            # during the fit both slopes are equal (the curve at the load does not depend
            # on them, and a2_h >= a2_c then holds at every load); :meth:`settle` chooses
            mean = 0.5 * (self.base_slopes[0] + self.base_slopes[1])
            self.slopes = (mean, mean)
            self.names = [f"tau{s}_c", f"gap{s}"]

    def bounds(self, name):
        low, high = self.temperatures
        return (0.0, high - low) if name.startswith("gap") else (low, high)

    def start(self, lines):
        """{unknown: start} from ``lines`` = {"h": (intercept, slope), "c": (...)} of the
        centres against load (with one load: the centre there, slope ignored), inside the
        bounds."""
        (ah, bh), (ac, bc) = lines["h"], lines["c"]

        def lead(f):
            return ah + bh * f - ac - bc * f
        if not self.fit_slopes:
            f = self.load
            values = (ac + bc * f, max(lead(f), 0.5))
        else:
            (low, high), (g0, g1) = self.anchors, self.gap_anchors
            values = (ac + bc * low, ac + bc * high, max(lead(g0), 0.5), max(lead(g1), 0.5))
        return {name: min(max(v, self.bounds(name)[0]), self.bounds(name)[1])
                for name, v in zip(self.names, values)}

    def parameters(self, u):
        """{a_h, b_h, a_c, b_c (with the stage's prefix): value} from the unknowns ``u``
        (a dict holding this stage's names); linear in them."""
        s = self.prefix
        if self.fit_slopes:
            c_low, c_high, g_a, g_b = (u[n] for n in self.names)
            (low, high), (g0, g1) = self.anchors, self.gap_anchors
            b_c = (c_high - c_low) / (high - low)
            a_c = c_low - b_c * low
            lead_slope = (g_b - g_a) / (g1 - g0)
            b_h = b_c + lead_slope
            a_h = a_c + g_a - lead_slope * g0
        else:
            tau_c, gap = (u[n] for n in self.names)
            b_h, b_c = self.slopes
            a_c = tau_c - b_c * self.load
            a_h = tau_c + gap - b_h * self.load
        return {f"a{s}_h": a_h, f"b{s}_h": b_h, f"a{s}_c": a_c, f"b{s}_c": b_c}

    def settle(self, u, base_name):
        """After the fit, with one load: keep the base file's slopes (from ``base_name``)
        when the heating centre stays at or above the cooling one down to no load, else
        both take their mean; :attr:`slope_note` says which, and why."""
        if self.fit_slopes:
            self.slope_note = ""
            return
        s = self.prefix
        b_h, b_c = self.base_slopes
        gap = u[self.names[1]]
        lead_at_zero = gap - (b_h - b_c) * self.load
        which = f"b{s}_h, b{s}_c"
        if lead_at_zero >= 0.0:
            self.slopes = (b_h, b_c)
            self.slope_note = (f"{which} not fitted (one load): {b_h:g} and {b_c:g} degC/kg "
                               f"from {base_name}")
            return
        mean = 0.5 * (b_h + b_c)
        self.slopes = (mean, mean)
        self.slope_note = (
            f"{which} not fitted (one load): both {mean:g} degC/kg, the mean of {base_name}'s "
            f"{b_h:g} and {b_c:g}, because those would put the heating centre below the cooling "
            f"one at no load (hysteresis {gap:.3g} K at {self.load:g} kg, less than "
            f"{(b_h - b_c) * self.load:.3g} K)")

    def centre_at(self, u, load):
        """(heating, cooling) centre [degC] at ``load`` [kg]."""
        p = self.parameters(u)
        s = self.prefix
        return (p[f"a{s}_h"] + p[f"b{s}_h"] * load, p[f"a{s}_c"] + p[f"b{s}_c"] * load)
