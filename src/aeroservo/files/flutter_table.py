"""A flutter sweep as a table: one row per mode and speed, like Nastran's f06 flutter summary.

Columns (CSV, units in the names): ``mode``, ``mode_label``, ``point``, ``velocity_m_s``,
``eas_m_s``, ``velocity_kt``, ``eas_kt`` (EAS and knots when the density is known, which it
always is), ``mach`` (empty without a speed of sound), ``damping_g`` (``g = -2 zeta``, > 0
unstable), ``damping_zeta``, ``frequency_hz``, ``eigenvalue_real_1_s``,
``eigenvalue_imag_1_s``, ``exact`` (1 where the value is an eigenvalue of the full model),
``method`` (``time-domain`` or ``p-k``). pyNastran users read it with ``pandas.read_csv`` and
group by ``mode`` as they would ``flutter_response`` tables.
"""

from __future__ import annotations

import csv
import io

import numpy as np

from ..aero.atmosphere import KNOT
from ..stability.result import FlutterResult

__all__ = ["COLUMNS", "flutter_table"]

COLUMNS = (
    "mode",
    "mode_label",
    "point",
    "velocity_m_s",
    "eas_m_s",
    "velocity_kt",
    "eas_kt",
    "mach",
    "damping_g",
    "damping_zeta",
    "frequency_hz",
    "eigenvalue_real_1_s",
    "eigenvalue_imag_1_s",
    "exact",
    "method",
)


def _rows(result: FlutterResult, method: str):
    zeta = result.damping_ratio
    freq = result.frequencies
    exact = result.exact if result.exact is not None else np.ones(zeta.shape, dtype=bool)
    for j, label in enumerate(result.mode_labels):
        for i, v in enumerate(result.speeds):
            lam = result.eigenvalues[i, j]
            if not np.isfinite(lam):  # a p-k branch that ended
                continue
            eas = result.eas(float(v))
            mach = result.mach_of(float(v))
            yield (
                j + 1,
                label,
                i + 1,
                f"{v:.10g}",
                f"{eas:.10g}",
                f"{v / KNOT:.10g}",
                f"{eas / KNOT:.10g}",
                "" if mach is None else f"{mach:.6g}",
                f"{-2 * zeta[i, j]:.8g}",
                f"{zeta[i, j]:.8g}",
                f"{freq[i, j]:.8g}",
                f"{lam.real:.10g}",
                f"{lam.imag:.10g}",
                int(exact[i, j]),
                method,
            )


def flutter_table(result: FlutterResult, pk: FlutterResult | None = None) -> str:
    """CSV text of a sweep (and of its p-k sweep, rows marked ``method = p-k``)."""
    out = io.StringIO()
    w = csv.writer(out, lineterminator="\n")
    w.writerow(COLUMNS)
    w.writerows(_rows(result, "time-domain"))
    if pk is not None:
        w.writerows(_rows(pk, "p-k"))
    return out.getvalue()
