"""Assembly of the speed- and density-independent matrices of a wing stick model (seed eq. 6-7).

Everything here runs once per (wing, mesh); speeds and densities only scale the results
(:mod:`aeroservo.system`).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..aero.theodorsen import SectionAero, section_aero
from ..structure.beam_element import field_shapes, gauss_rule, integrate, lag_shapes, point_shapes
from ..structure.mesh import Mesh
from ..structure.wing import Wing
from .matrices import AeroMatrices, StripGroup
from .point_masses import point_mass_blocks
from .swept_assembly import gradient_shapes, kink_transforms, strip_coefficients, to_nodal

__all__ = ["assemble", "element_properties", "section_coefficients"]


def element_properties(wing: Wing, mesh: Mesh) -> dict[str, np.ndarray]:
    """Section properties per element (constant within an element by construction of the mesh).

    Returns a dict of arrays of length n_elements: ``b, a, mass, x_alpha, s_alpha, inertia, EI,
    GJ`` of
    the wing and ``c, s_beta, i_beta, GJ_f, k_delta`` of the flap (c = 1 and zeros where there
    is no control surface: a zero-chord flap, whose aerodynamic terms all vanish).
    """
    segs = [wing.segments[i] for i in mesh.segment]
    p = {
        "b": np.array([s.semichord for s in segs]),
        "a": np.array([s.a for s in segs]),
        "mass": np.array([s.mass for s in segs]),
        "x_alpha": np.array([s.x_alpha for s in segs]),
        "s_alpha": np.array([s.static_moment for s in segs]),
        "inertia": np.array([s.inertia for s in segs]),
        "EI": np.array([s.EI for s in segs]),
        "GJ": np.array([s.GJ for s in segs]),
    }
    n = mesh.n_elements
    c = np.ones(n)
    s_b, i_b, gj_f, k_d = (np.zeros(n) for _ in range(4))
    for e, k in enumerate(mesh.surface):
        if k >= 0:
            cs = wing.control_surfaces[k]
            c[e], s_b[e], i_b[e], gj_f[e], k_d[e] = (
                cs.hinge,
                cs.static_moment,
                cs.inertia,
                cs.GJ,
                cs.hinge_stiffness,
            )
    p.update(c=c, s_beta=s_b, i_beta=i_b, GJ_f=gj_f, k_delta=k_d)
    return p


def section_coefficients(p: dict) -> tuple[np.ndarray, np.ndarray, np.ndarray, SectionAero]:
    """Section matrices on ``[w, phi, delta]`` per element from :func:`element_properties`.

    Returns ``(ms, kd, kn, aero)``: structural mass (n_el, 3, 3) [kg/m, kg m/m, kg m],
    stiffness of the strains ``[w'', phi', delta']`` [N m^2] and of the unknowns (hinge springs)
    [N m/rad per m], and the Theodorsen coefficients. Flap terms vanish where there is no flap.
    Complex properties give complex coefficients (complex-step derivatives).
    """
    b = p["b"]
    n_el = b.shape[0]
    dtype = np.result_type(*p.values(), float)
    y_h = b * (p["c"] - p["a"])
    ms = np.zeros((n_el, 3, 3), dtype)
    ms[:, 0, 0] = p["mass"]
    ms[:, 0, 1] = ms[:, 1, 0] = -p["mass"] * p["x_alpha"] * b  # S_alpha = m x_alpha b
    ms[:, 0, 2] = ms[:, 2, 0] = -p["s_beta"]
    ms[:, 1, 1] = p["inertia"]
    ms[:, 1, 2] = ms[:, 2, 1] = p["i_beta"] + y_h * p["s_beta"]
    ms[:, 2, 2] = p["i_beta"]
    kd = np.zeros((n_el, 3, 3), dtype)
    kd[:, 0, 0], kd[:, 1, 1], kd[:, 2, 2] = p["EI"], p["GJ"], p["GJ_f"]
    kn = np.zeros((n_el, 3, 3), dtype)
    kn[:, 2, 2] = p["k_delta"]
    return ms, kd, kn, section_aero(b, p["a"], p["c"])


def scatter_blocks(
    blocks: np.ndarray, rows: np.ndarray, cols: np.ndarray, shape: tuple[int, int]
) -> sp.csr_matrix:
    """Sum element blocks (n_el, p, q) into a sparse matrix, dropping removed unknowns (-1)."""
    r = np.broadcast_to(rows[:, :, None], blocks.shape)
    c = np.broadcast_to(cols[:, None, :], blocks.shape)
    keep = (r >= 0) & (c >= 0) & (blocks != 0.0)
    mat = sp.coo_matrix((blocks[keep], (r[keep], c[keep])), shape=shape)
    return mat.tocsr()


def assemble(wing: Wing, mesh: Mesh, *, sweep_terms: str = "full") -> AeroMatrices:
    """Build the structural and aerodynamic influence matrices of a wing.

    Parameters
    ----------
    wing : Wing
    mesh : Mesh
        From :func:`aeroservo.structure.mesh.build_mesh`.
    sweep_terms : {"full", "classical"}
        Spanwise-convection terms of swept segments (``docs/sweep.md``).

    Returns
    -------
    AeroMatrices
    """
    p = element_properties(wing, mesh)
    L = mesh.lengths
    xi, wts = gauss_rule()
    N, D, S = field_shapes(L, xi)
    n_el = mesh.n_elements
    nz = lag_shapes(xi)[None, :, None, :].repeat(n_el, axis=0)  # (n_el, n_g, 1, 2)

    ms, kd, kn, aero = section_coefficients(p)
    c = strip_coefficients(wing, mesh, aero, p["b"], sweep_terms)  # modified strips if swept
    N1 = gradient_shapes(N, D, S)  # [w', phi', delta'], convected by a swept wing's spanwise flow
    kinks = kink_transforms(wing, mesh)  # None unless the sweep changes between segments

    def elem(left, coef, right):
        return integrate(L, wts, left, coef[:, None], right)

    # unknowns in an extended numbering: the clamped root (w, theta, phi) get the last 3 indices,
    # so one scatter gives both the free matrices and the root-reaction rows
    n_q = mesh.n_dofs
    edofs = extended_dofs(mesh)
    n_x = n_q + 3
    n_n = mesh.n_nodes
    lag_dofs = np.stack([np.arange(n_el), np.arange(n_el) + 1], axis=1)

    crows = cut_rows(mesh)

    def split(blocks, rows, cols, shape):
        """Scatter, then split extended structural rows/columns into free and reaction parts:
        ``(root rows, cut rows)`` when ``rows`` are the structural unknowns."""
        blocks = to_nodal(blocks, kinks, rows is edofs, cols is edofs)  # a cranked axis
        full = scatter_blocks(blocks, rows, cols, shape)
        if cols is edofs:
            full = full[:, :n_q]
        if rows is edofs:
            cut = scatter_blocks(blocks, crows, cols, (3 * n_n, shape[1]))
            return full[:n_q], (full[n_q:], cut[:, :n_q] if cols is edofs else cut)
        return full, None

    def qq(coef, left=N, right=N):
        return split(elem(left, coef, right), edofs, edofs, (n_x, n_x))

    m_blocks = elem(N, ms, N) + point_mass_blocks(wing, mesh)  # + 0.0 without masses
    Ms, Ms_r = split(m_blocks, edofs, edofs, (n_x, n_x))
    # the loads of a unit vertical acceleration of every point (the wing's weight per g): the
    # mass blocks applied to a rigid vertical translation (w = 1, no slope, twist or flap)
    rigid = np.array([1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    w_el = to_nodal(m_blocks, kinks, True, True) @ rigid
    weight = _scatter_vector(w_el, edofs, n_x)
    weight_c = _scatter_vector(w_el, crows, 3 * n_n)
    parts, parts_r = {}, {}
    for i, name in enumerate(("bending", "torsion")):
        parts[name], parts_r[name] = qq(kd * _unit(i), D, D)
    k_act = actuator_stiffness(wing, mesh, n_q)
    flap_all = qq(kd * _unit(2), D, D)[0] + qq(kn)[0] + k_act
    for k, cs in enumerate(wing.control_surfaces):
        mask = np.zeros(n_q)
        d = mesh.dof_delta[k]
        mask[d[d >= 0]] = 1.0
        dm = sp.diags(mask)
        parts[f"flap ({cs.name})"] = (dm @ flap_all @ dm).tocsr()
    Ks = parts["bending"] + parts["torsion"] + flap_all
    # flap unknowns are never clamped; a cut of the wing box carries no flap strain
    Ks_r = tuple(parts_r["bending"][i] + parts_r["torsion"][i] for i in (0, 1))

    # circulatory matrices and load vectors grouped by semichord (exact C(k), gusts)
    groups, groups_r = [], []
    ones_z = np.ones((n_el, 1, 1))
    for b in np.unique(c["b"]):  # the semichord of the reduced frequency (b / cos(sweep))
        sel = (c["b"] == b).astype(float)[:, None, None]
        pq, pq_r = qq(c["Pq"] * sel)
        if c["Pg"] is not None:
            pg, pg_r = qq(c["Pg"] * sel, N, N1)
            pq, pq_r = pq + pg, tuple(x + y for x, y in zip(pq_r, pg_r, strict=True))
        pd, pd_r = qq(c["Pd"] * sel)
        gw_blocks = to_nodal(elem(N, c["w"][:, :, None] * sel, nz), kinks, True, False)
        # lag shape functions sum to one
        gw = np.asarray(scatter_blocks(gw_blocks, edofs, lag_dofs, (n_x, n_n)).sum(axis=1))
        gw_c = np.asarray(scatter_blocks(gw_blocks, crows, lag_dofs, (3 * n_n, n_n)).sum(axis=1))
        groups.append(StripGroup(float(b), pq, pd, gw.ravel()[:n_q]))
        groups_r.append(
            tuple(
                StripGroup(float(b), pq_r[i], pd_r[i], g)
                for i, g in enumerate((gw.ravel()[n_q:], gw_c.ravel()))
            )
        )

    # lag fields: term-independent base matrices on the nodes
    Mz1 = scatter_blocks(elem(nz, ones_z, nz), lag_dofs, lag_dofs, (n_n, n_n))
    Lz1 = scatter_blocks(elem(nz, c["inv_b"][:, None, None], nz), lag_dofs, lag_dofs, (n_n, n_n))
    E1 = split(elem(nz, c["r_q"][:, None, :], N), lag_dofs, edofs, (n_n, n_x))[0]
    if c["r_g"] is not None:
        E1 = E1 + split(elem(nz, c["r_g"][:, None, :], N1), lag_dofs, edofs, (n_n, n_x))[0]
    F1 = split(elem(nz, c["r_d"][:, None, :], N), lag_dofs, edofs, (n_n, n_x))[0]
    W1, W1_r = split(elem(N, c["w"][:, :, None], nz), edofs, lag_dofs, (n_x, n_n))
    Mnc, Mnc_r = qq(c["Mnc"])
    Cnc, Cnc_r = qq(c["Cnc"])
    Knc, Knc_r = qq(c["Knc"])

    labels = tuple(str(i) for i in range(n_n))
    root, cuts = (
        AeroMatrices(
            Ms=Ms_r[i],
            Ks=Ks_r[i],
            Mnc=Mnc_r[i],
            Cnc=Cnc_r[i],
            Knc=Knc_r[i],
            circ_groups=tuple(g[i] for g in groups_r),
            Mz1=Mz1,
            Lz1=Lz1,
            E1=E1,
            F1=F1,
            W1=W1_r[i],
            dof_labels=mesh.dof_labels,
            lag_labels=labels,
            weight=(weight[n_q:], weight_c)[i],
        )
        for i in (0, 1)
    )
    return AeroMatrices(
        Ms=Ms,
        Ks=Ks,
        Mnc=Mnc,
        Cnc=Cnc,
        Knc=Knc,
        circ_groups=tuple(groups),
        Mz1=Mz1,
        Lz1=Lz1,
        E1=E1,
        F1=F1,
        W1=W1,
        dof_labels=mesh.dof_labels,
        lag_labels=labels,
        stiffness_parts=parts,
        root=root,
        cuts=cuts,
        weight=weight[:n_q],
    )


def extended_dofs(mesh: Mesh) -> np.ndarray:
    """Element unknowns with the clamped root's (w, theta, phi) numbered n_q, n_q+1, n_q+2, so
    one scatter gives the free matrices and the root rows."""
    n_q = mesh.n_dofs
    edofs = mesh.element_dofs.copy()
    edofs[0, [0, 1, 4]] = [n_q, n_q + 1, n_q + 2]
    return edofs


def _scatter_vector(values: np.ndarray, rows: np.ndarray, n: int) -> np.ndarray:
    """Sum element vectors (n_el, p) into a vector of length n, dropping removed unknowns."""
    out = np.zeros(n)
    keep = rows >= 0
    np.add.at(out, rows[keep], values[keep])
    return out


def cut_rows(mesh: Mesh) -> np.ndarray:
    """Element unknowns numbered as the rows of the internal loads at each node: the
    ``(w, theta, phi)`` of an element's inboard node ``j`` become rows ``3j, 3j + 1, 3j + 2``,
    every other unknown is dropped (-1). Scattered with these rows, the elements outboard of a
    node give the loads the inboard part carries there (shear, bending moment, torque): the
    reactions of the outboard part clamped at that node, as the root rows for the root."""
    rows = np.full(mesh.element_dofs.shape, -1)
    j = np.arange(mesh.n_elements)
    rows[:, 0], rows[:, 1], rows[:, 4] = 3 * j, 3 * j + 1, 3 * j + 2
    return rows


def _unit(i: int) -> np.ndarray:
    out = np.zeros((1, 3, 3))
    out[0, i, i] = 1.0
    return out


def actuator_stiffness(wing: Wing, mesh: Mesh, n_q: int) -> sp.csr_matrix:
    """Point springs k_act delta_D(x - x_a) acting on the flap rotation of their surface."""
    k = sp.csr_matrix((n_q, n_q))
    for i, cs in enumerate(wing.control_surfaces):
        for act in cs.actuators:
            r = actuator_row(wing, mesh, n_q, i, act)
            k = k + act.stiffness * sp.csr_matrix(np.outer(r, r))
    return k


def actuator_row(wing: Wing, mesh: Mesh, n_q: int, surface: int, act) -> np.ndarray:
    """The row ``r`` with ``delta(x_a) = r @ q``: the rotation of control surface number
    ``surface`` at the station of its actuator ``act`` [rad per unit of the unknowns]."""
    own = np.flatnonzero(mesh.surface == surface)
    x = act.station
    i = np.searchsorted(mesh.nodes[own + 1], x - 1e-12 * wing.span)
    e = own[min(i, own.size - 1)]
    xi = (x - mesh.nodes[e]) / (mesh.nodes[e + 1] - mesh.nodes[e])
    n, _ = point_shapes(mesh.lengths[e], float(np.clip(xi, 0.0, 1.0)))
    r = np.zeros(n_q)
    r[mesh.element_dofs[e, 6:8]] = n[2, 6:8]
    return r
