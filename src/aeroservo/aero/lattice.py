"""The boxes of a planar lifting surface for the doublet-lattice and vortex-lattice methods.

A lattice is a set of quadrilateral boxes in the wing plane z = 0, in aeroservo's axes
(``docs/conventions.md``: x spanwise from the root, y aft in the direction of the free stream,
z up). Each box has two **streamwise** side edges (constant x) and straight leading and trailing
edges, as in Nastran's CAERO1 (Albano and Rodden 1969):

* the doublet line (bound vortex) lies on the box's 1/4-chord line; a box's load acts at the
  middle of it, the **load point**;
* the boundary condition (normalwash) is met at the middle of the 3/4-chord line, the
  **downwash point**.

A box's corners are numbered as PanelAero numbers them: 1 inboard leading edge, 2 inboard
trailing edge, 3 outboard trailing edge, 4 outboard leading edge. ``symmetric`` means the root
plane x = 0 is a plane of symmetry (a wind-tunnel wall or the fuselage side of a half model):
the mirror image of the lattice is added with the same motion.
"""

from __future__ import annotations

import hashlib
from dataclasses import dataclass, field

import numpy as np

from ..errors import InputError

__all__ = ["Lattice", "strip_lattice"]


@dataclass(frozen=True)
class Lattice:
    """Boxes of a planar lifting surface.

    Attributes
    ----------
    corners : ndarray (n, 4, 2)
        Corner points ``(x, y)`` [m] of each box (order in the module notes).
    strip : ndarray (n,) of int
        Spanwise strip of each box (boxes of a strip share their side edges).
    row : ndarray (n,) of int
        Chordwise position of each box in its strip (0 at the leading edge).
    symmetric : bool
        The root plane x = 0 is a plane of symmetry (the mirror image moves with the wing).
    """

    corners: np.ndarray
    strip: np.ndarray
    row: np.ndarray
    symmetric: bool = True
    _key: list = field(default_factory=list, repr=False, compare=False)

    @property
    def n_boxes(self) -> int:
        return int(self.corners.shape[0])

    def _point(self, fraction: float) -> np.ndarray:
        """Mid-span point at ``fraction`` of each box's chord [m], shape (n, 2)."""
        c = self.corners
        inner = c[:, 0] + fraction * (c[:, 1] - c[:, 0])
        outer = c[:, 3] + fraction * (c[:, 2] - c[:, 3])
        return 0.5 * (inner + outer)

    @property
    def load_points(self) -> np.ndarray:
        """Middle of each box's 1/4-chord line (where its load acts) [m], (n, 2)."""
        return self._point(0.25)

    @property
    def downwash_points(self) -> np.ndarray:
        """Middle of each box's 3/4-chord line (where the normalwash is met) [m], (n, 2)."""
        return self._point(0.75)

    @property
    def chords(self) -> np.ndarray:
        """Mean streamwise chord of each box [m]."""
        c = self.corners
        return 0.5 * ((c[:, 1, 1] - c[:, 0, 1]) + (c[:, 2, 1] - c[:, 3, 1]))

    @property
    def widths(self) -> np.ndarray:
        """Spanwise width of each box [m]."""
        return self.corners[:, 3, 0] - self.corners[:, 0, 0]

    @property
    def areas(self) -> np.ndarray:
        """Area of each box [m^2] (a trapezoid: mean chord times width)."""
        return self.chords * self.widths

    def key(self) -> str:
        """A digest of the geometry (corners to 1e-12 m and the symmetry), for the AIC cache."""
        if not self._key:
            h = hashlib.sha256()
            h.update(np.round(self.corners, 12).astype("<f8").tobytes())
            h.update(b"symmetric" if self.symmetric else b"free")
            self._key.append(h.hexdigest())
        return self._key[0]

    def aerogrid(self, mirror: bool = False) -> dict:
        """The box set as PanelAero's ``aerogrid`` dictionary (its axes: X streamwise = our y,
        Y spanwise = our x, Z up).

        Parameters
        ----------
        mirror : bool
            Append the mirror image in the root plane (boxes numbered n..2n-1, each defined
            from left to right with its normal up, as PanelAero requires).
        """
        c = self.corners
        if mirror:
            m = c[:, [3, 2, 1, 0]].copy()  # outboard edge becomes the left (inboard) one
            m[..., 0] *= -1.0
            c = np.concatenate([c, m])
        pts = c[..., ::-1]  # (X, Y) = (y, x)

        def xyz(a: np.ndarray) -> np.ndarray:
            return np.column_stack([a, np.zeros(len(a))])

        l1 = pts[:, 1] - pts[:, 0]
        l2 = pts[:, 2] - pts[:, 3]
        b1 = pts[:, 3] - pts[:, 0]
        lm = 0.5 * (l1 + l2)
        n = len(pts)
        return {
            "n": n,
            "l": lm[:, 0].copy(),
            "A": np.abs(lm[:, 0] * b1[:, 1]),
            "N": np.tile([0.0, 0.0, 1.0], (n, 1)),
            "offset_l": xyz(pts[:, 0] + 0.25 * lm + 0.5 * b1),
            "offset_k": xyz(pts[:, 0] + 0.50 * lm + 0.5 * b1),
            "offset_j": xyz(pts[:, 0] + 0.75 * lm + 0.5 * b1),
            "offset_P1": xyz(pts[:, 0] + 0.25 * l1),
            "offset_P3": xyz(pts[:, 3] + 0.25 * l2),
        }


def strip_lattice(
    x_edges: np.ndarray,
    leading_edge: np.ndarray,
    chord: np.ndarray,
    fractions: list[np.ndarray],
    *,
    symmetric: bool = True,
) -> Lattice:
    """A lattice of spanwise strips, each divided chordwise at given fractions of its chord.

    Parameters
    ----------
    x_edges : ndarray (n_strips, 2)
        Inboard and outboard spanwise stations of each strip [m], inboard < outboard.
    leading_edge : ndarray (n_strips, 2)
        Chordwise position y of the leading edge at the two side edges [m].
    chord : ndarray (n_strips, 2)
        Streamwise chord at the two side edges [m], > 0.
    fractions : list of ndarray
        Per strip, the chordwise division points as fractions of the local chord, increasing
        from 0 to 1 (a hinge line at a constant fraction is then a box edge).
    symmetric : bool
        The root plane x = 0 is a plane of symmetry.

    Returns
    -------
    Lattice
    """
    x_edges = np.asarray(x_edges, dtype=float)
    le = np.asarray(leading_edge, dtype=float)
    ch = np.asarray(chord, dtype=float)
    n_s = x_edges.shape[0]
    if x_edges.shape != (n_s, 2) or le.shape != (n_s, 2) or ch.shape != (n_s, 2) or n_s == 0:
        raise InputError("lattice: x_edges, leading_edge and chord must all be (n_strips, 2)")
    if len(fractions) != n_s:
        raise InputError(f"lattice: {len(fractions)} chordwise divisions for {n_s} strips")
    if not (np.all(np.isfinite(x_edges)) and np.all(np.isfinite(le)) and np.all(np.isfinite(ch))):
        raise InputError("lattice: the strip geometry has NaN or infinite values")
    if np.any(x_edges[:, 1] <= x_edges[:, 0]) or np.any(ch <= 0.0):
        raise InputError("lattice: every strip needs a positive width and chord")
    if symmetric and np.any(x_edges[:, 0] < -1e-12 * max(1.0, float(np.abs(x_edges).max()))):
        raise InputError("lattice: a symmetric lattice must lie at x >= 0 (the root plane)")
    corners, strips, rows = [], [], []
    for s in range(n_s):
        f = np.asarray(fractions[s], dtype=float)
        if f.ndim != 1 or f.size < 2 or f[0] != 0.0 or f[-1] != 1.0 or np.any(np.diff(f) <= 0):
            raise InputError(f"lattice: strip {s}: chordwise fractions must rise from 0 to 1")
        (xi, xo), (li, lo), (ci, co) = x_edges[s], le[s], ch[s]
        for r in range(f.size - 1):
            f0, f1 = f[r], f[r + 1]
            corners.append(
                [
                    [xi, li + f0 * ci],
                    [xi, li + f1 * ci],
                    [xo, lo + f1 * co],
                    [xo, lo + f0 * co],
                ]
            )
            strips.append(s)
            rows.append(r)
    return Lattice(
        np.asarray(corners, dtype=float),
        np.asarray(strips, dtype=int),
        np.asarray(rows, dtype=int),
        bool(symmetric),
    )
