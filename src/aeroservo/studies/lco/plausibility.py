"""Plausibility of a limit-cycle study's hinge laws for the linear aerodynamics of its model:
warnings (not refusals) for the run's notes, each naming the key and its value."""

from __future__ import annotations

import numpy as np

__all__ = ["PLAUSIBLE_EDGE", "plausibility_notes"]


PLAUSIBLE_EDGE = 0.1
"""Largest rotation [rad] (5.7 deg) of a gap's edge from the neutral position, or of a cubic
law's own scale, before the run warns: a freeplay limit cycle swings the surface about one
total gap (half peak-to-peak 0.9 to 1 gap on the Conner section), so a 0.2 rad gap centred at
zero (edges at +-5.7 deg) already swings it +-11 deg, about where a plain flap's lift stops
growing linearly with its deflection; the linear (attached-flow) aerodynamics of these models
know nothing of that. The gap of Conner et al. is 0.074 rad (edges at +-2.1 deg)."""


def plausibility_notes(setup, where: str = "hinges") -> list[str]:
    """Warnings (not refusals) for the hinge laws of ``setup`` (an
    :class:`~aeroservo.studies.lco.study.LCOSetup`) whose motion lies beyond what linear
    aerodynamics describe: a gap whose farther edge lies more than :data:`PLAUSIBLE_EDGE` from
    zero, a cubic law whose cubic term equals its linear one only beyond it. ``where`` names
    the hinge tables (``"lco.hinges"``, or a wing file's ``[[hinges]]``)."""
    notes = []
    where = where.replace(" [[hinges]]", ": hinges")  # a wing file's tables
    for i, h in enumerate(setup.hinges):
        law = h.law
        gap = getattr(law, "gap", None)
        if gap:
            offset = float(getattr(law, "offset", 0.0))
            edge = abs(offset) + 0.5 * gap
            if edge <= PLAUSIBLE_EDGE:
                continue
            key, value = ("gap", gap) if 0.5 * gap > PLAUSIBLE_EDGE else ("offset", offset)
            notes.append(
                f"warning: {where}[{i}].{key} = {value:g} rad: the gap's edge lies "
                f"{np.degrees(edge):.3g} deg from zero and its limit cycles swing {h.target!r} "
                f"by about one gap ({np.degrees(gap):.3g} deg), beyond the "
                f"{np.degrees(PLAUSIBLE_EDGE):.2g} deg within which the linear aerodynamics of "
                "this model hold: its amplitudes and onsets are the model's, not a wing's"
            )
            continue
        c = getattr(law, "coefficient", None)
        ks = [k for k, el_law in zip(setup.elements.stiffness, setup.elements.laws, strict=True)
              if el_law is law]  # fmt: skip
        if not c or not ks:
            continue
        scale = float(np.sqrt(min(abs(k) for k in ks) / abs(c)))
        if scale > PLAUSIBLE_EDGE:
            notes.append(
                f"warning: {where}[{i}].coefficient = {c:g} N m/rad^3: its cubic term equals the "
                f"linear one only at {scale:.3g} rad ({np.degrees(scale):.3g} deg) of "
                f"{h.target!r}, beyond the {np.degrees(PLAUSIBLE_EDGE):.2g} deg within which the "
                "linear aerodynamics of this model hold: the motion it shapes is the model's, not "
                "a wing's"
            )
    return notes
