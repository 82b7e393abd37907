"""The time-domain onsets of a doublet-lattice model checked against its exact forces.

A doublet-lattice model marches in time with a rational-function approximation (RFA) of its
generalized aerodynamic forces (:mod:`aeroservo.aero.rfa`). A fit can be wrong where it
matters: an error near the flutter frequency moves the onset, and lag terms can couple into
spurious instabilities that the tabulated forces do not have. Every onset the time-domain search
reports is therefore checked with the tabulated forces themselves (the p-k problem of
:class:`aeroservo.stability.pk_frozen._PKDLM`, frozen at the onset's frequency and iterated
until ``Im p = omega``): the exact forces' damping at the onset speed and one per cent above it
give, by linear extrapolation, the exact-force onset speed ``V_pk``. The check reports

* ``|V_rfa / V_pk - 1|`` above :data:`ONSET_TOL`, with the fit error that explains it;
* an onset the exact forces do not confirm (no p-k root within :data:`FREQ_TOL` of the onset
  frequency, or one that stays stable over the one-per-cent step): likely an artefact of the
  fit.

The full p-k sweep (:func:`aeroservo.stability.pk.pk_flutter`) remains the reference; this
check costs a few frozen eigenproblems per onset.
"""

from __future__ import annotations

import numpy as np

from .pk_frozen import PKConvergenceError, _setup_dlm
from .result import FlutterResult

__all__ = ["rfa_onset_notes", "ONSET_TOL", "FREQ_TOL", "STEP"]

ONSET_TOL = 5e-3
"""Relative difference between the RFA onset and the exact-force estimate that is reported."""

FREQ_TOL = 0.2
"""Relative distance of the nearest exact-force root from the onset frequency that counts as
no root at all."""

STEP = 0.01
"""Relative speed step of the extrapolation to the exact-force onset."""


def _nearest_root(pk, speed: float, omega: float) -> tuple[complex, np.ndarray]:
    """The exact-force eigenpair nearest ``i omega`` of the problem frozen at ``omega``."""
    K, C = pk.frozen(speed, omega)
    n = K.shape[0]
    Minv = np.linalg.inv(pk.M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
    lam, X = np.linalg.eig(A)
    j = int(np.argmin(np.abs(lam - 1j * omega)))
    return complex(lam[j]), X[:n, j]


def rfa_onset_notes(model, result: FlutterResult, mach: float) -> tuple[list[str], list[dict]]:
    """Warnings and per-onset records of the exact-force check (see the module notes).

    Parameters
    ----------
    model : AeroelasticModel
        A doublet-lattice model.
    result : FlutterResult
        Its time-domain boundary.
    mach : float
        The Mach number of the boundary.

    Returns
    -------
    warnings : list of str
    records : list of dict
        Per onset: ``speed`` [m/s], ``frequency`` [Hz], ``pk_speed`` [m/s] (None when the exact
        forces give no onset nearby), ``difference`` (relative) and ``reduced_frequency``
        (``omega b_ref / V``; above the tabulated range it gets a warning too).
    """
    onsets = [c for c in result.crossings if c.kind == "onset"]
    if not onsets:
        return [], []
    pk, _phi, _ = _setup_dlm(model, result.density, mach)
    err = float(model.dlm_fit(mach).error.max())
    notes: list[str] = []
    records: list[dict] = []
    for c in onsets:
        omega = 2 * np.pi * c.frequency
        v_pk = None
        try:
            p0, q0 = _nearest_root(pk, c.speed, omega)
            if abs(abs(p0.imag) - omega) > FREQ_TOL * omega:
                raise PKConvergenceError("no root near the onset frequency")
            p1, q1 = pk.converge(c.speed, p0, q0)
            p2, _ = pk.converge(c.speed * (1 + STEP), p1, q1)
            slope = (p2.real - p1.real) / (STEP * c.speed)
            if slope > 0:
                v_pk = float(c.speed - p1.real / slope)
        except (PKConvergenceError, np.linalg.LinAlgError):
            v_pk = None
        diff = None if v_pk is None or v_pk <= 0 else float(c.speed / v_pk - 1)
        records.append(
            {"speed": c.speed, "frequency": c.frequency, "pk_speed": v_pk, "difference": diff}
        )
        k_onset = omega * model.dlm.b_ref / c.speed
        k_max = float(model.dlm.settings.k_values[-1])
        records[-1]["reduced_frequency"] = float(k_onset)
        if k_onset > k_max:
            notes.append(
                f"the onset at {c.speed:.5g} m/s ({c.frequency:.4g} Hz) has the reduced frequency "
                f"k = {k_onset:.3g}, above the tabulated k <= {k_max:.3g}: its forces are the "
                f"fit's extrapolation; tabulate up to k = {1.5 * k_onset:.2g} (dlm.k_max)"
            )
        if diff is None or abs(diff) > 10 * STEP:
            notes.append(
                f"the time-domain onset at {c.speed:.5g} m/s ({c.frequency:.4g} Hz) is not "
                "confirmed by the tabulated doublet-lattice forces (p-k): likely an artefact of "
                f"the rational-function fit (largest fit error {err:.3g}); check with the p-k "
                "(--pk) and try fewer lag roots or a narrower k range"
            )
        elif abs(diff) > ONSET_TOL:
            notes.append(
                f"the time-domain onset at {c.speed:.5g} m/s differs by {100 * diff:+.2f} % from "
                f"the tabulated doublet-lattice forces' ({v_pk:.5g} m/s, p-k): the "
                f"rational-function fit's error (largest {err:.3g}) near {c.frequency:.4g} Hz"
            )
    return notes, records
