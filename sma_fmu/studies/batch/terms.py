"""The optional model terms of the batch plants (runtime/model_terms.py): a base of BatchPlant.

Per run: dH/k_B of heating and of cooling (nu_h, nu_c), the second stage's M1, M2, -dH2/k_B
and 1/tau2_K of either direction (0 for a one-stage run, so the two-stage sum is its
one-stage split exactly), and the stressed lengths of its load segment.
"""
import numpy as np

from sma_fmu.studies.batch.branches import major_fractions, two_stage_fractions

__all__ = ["PlantTerms"]


class PlantTerms:
    """Arrays and helpers of the terms; BatchPlant sets ``M``, ``minus_energy``, ``inverse``,
    ``_energies`` and ``_centres`` ([heating; cooling] rows)."""

    def _terms_arrays(self, p, n):
        """The optional model terms: which are on in some run, and their per-run arrays."""
        self.two_stage = any(params.terms.two_stage for params in p)
        self.strain = any(params.terms.strain for params in p)
        self.M1, self.M2, self.minus_energy2 = np.empty(n), np.empty(n), np.empty(n)
        self._energies2, self._centres2 = np.zeros((2, n)), np.zeros((2, n))
        self.inverse2 = np.zeros(n)
        # l_M, l_F [m] of each run's load segment, and those of the present state (the
        # segment of the last step: a load change takes effect with the next step)
        self._segment_lengths, self.lengths = np.empty((2, n)), np.empty((2, n))
        self._expansion = {name: np.array([getattr(params.terms, name) for params in p])
                           for name in ("alpha_P", "alpha_MF", "T_alpha")}

    def _set_terms(self, at, rows, runs):
        """The terms of ``runs`` at the constants-table ``rows`` (their load segments)."""
        self._energies[1, runs] = -at["energy_cooling"][rows, runs]
        self.M1[runs], self.M2[runs] = at["M1"][rows, runs], at["M2"][rows, runs]
        self._energies2[0, runs] = -at["energy2_heating"][rows, runs]
        self._energies2[1, runs] = -at["energy2_cooling"][rows, runs]
        self._centres2[0, runs] = at["inv2_heating"][rows, runs]
        self._centres2[1, runs] = at["inv2_cooling"][rows, runs]
        self._segment_lengths[0, runs] = at["length_M"][rows, runs]
        self._segment_lengths[1, runs] = at["length_F"][rows, runs]

    def _direct_terms(self, masks, pair):
        """-dH/k_B (and stage 2's -dH2/k_B, 1/tau2_K) of each run's direction; exactly one
        of the two masked terms is nonzero."""
        np.multiply(self._energies, masks, pair)
        np.add(pair[0], pair[1], self.minus_energy)
        if self.two_stage:
            np.multiply(self._centres2, masks, pair)
            np.add(pair[0], pair[1], self.inverse2)
            np.multiply(self._energies2, masks, pair)
            np.add(pair[0], pair[1], self.minus_energy2)

    def _stages(self, runs, heating=None):
        """The two-stage constants of ``runs`` in their present direction (or ``heating``)."""
        if heating is None:
            return {"M1": self.M1[runs], "M2": self.M2[runs],
                    "minus_energy": self.minus_energy[runs],
                    "minus_energy2": self.minus_energy2[runs],
                    "inverse": self.inverse[runs], "inverse2": self.inverse2[runs]}
        row = 0 if heating else 1
        return {"M1": self.M1[runs], "M2": self.M2[runs],
                "minus_energy": self._energies[row][runs],
                "minus_energy2": self._energies2[row][runs],
                "inverse": self._centres[row][runs], "inverse2": self._centres2[row][runs]}

    def _major(self, temperature, runs, heating=None):
        """(xi_MF, xi_P) of the major branches of ``runs`` at ``temperature`` [degC]."""
        if self.two_stage:
            return two_stage_fractions(temperature, self._stages(runs, heating))
        if heating is None:
            return major_fractions(temperature, self.M[runs], self.minus_energy[runs],
                                   self.inverse[runs])
        row = 0 if heating else 1
        return major_fractions(temperature, self.M[runs], self._energies[row][runs],
                               self._centres[row][runs])
