"""The records of one flight point of a gust-loads study: plain JSON values (SI units,
radians) and the history arrays, as :class:`~aeroservo.studies.gust.results.GustLoadsResult`
holds them and :mod:`aeroservo.files.gust_loads_file` writes them."""

from __future__ import annotations

import numpy as np

__all__ = ["point_records", "totals"]


def _extreme_record(
    e, turb, u_sig: float, rigid: float | None = None, one_g: float | None = None
) -> dict:
    rec = {"unit": e.unit}
    for side in ("max", "min"):
        value, h, t, sign, corr = e.side(side)
        rec.update(
            {
                side: value,
                f"{side}_gradient": h,
                f"{side}_time": t,
                f"{side}_sign": sign,
                f"{side}_correlated": dict(corr),
            }
        )
    rec["discrete"] = max(abs(e.maximum), abs(e.minimum))
    if rigid is not None:
        rec["rigid"] = rigid
    if one_g is not None:
        rec["one_g"] = one_g
    if turb is not None and e.load in turb.a_bar:
        rec.update(
            a_bar=turb.a_bar[e.load], n0=turb.n0[e.load], turbulence=u_sig * turb.a_bar[e.load]
        )
    return rec


def point_records(index: int, pl, loads) -> tuple[list[dict], dict]:
    """JSON records and history arrays of one :class:`~aeroservo.studies.gust.point.PointLoads`
    (``index``: its place in the study); the records keep ``loads`` and the controls applied,
    the histories every output."""
    p = pl.point
    base = {
        "point": index,
        "mass_case": p.mass_case,
        "altitude": p.altitude,
        "speed_name": p.speed_name,
        "eas": p.speed,
        "tas": p.tas,
        "density": p.density,
        "f_g": pl.f_g,
        "u_sigma": pl.u_sigma,
        "open_loop_stable": pl.open_loop_stable,
        "trim": dict(pl.trim),
        "notes": list(pl.notes),
        "elapsed": pl.elapsed,
    }
    records, arrays = [], {}
    for loop, d in pl.discrete.items():
        turb = pl.turbulence.get(loop)
        rec = dict(base, loop=loop, controller=d.controller, gust_speed=d.speed)
        keep = [n for n in d.extremes if n in loads or n in d.limited]
        rec["loads"] = {
            n: _extreme_record(d.extremes[n], turb, pl.u_sigma, pl.rigid.get(n), pl.one_g.get(n))
            for n in keep
        }
        rec["time_at_limit"] = {c: float(np.max(a)) for c, a in d.limited.items()}
        rec["gradients"] = [float(h) for h in d.gradients]
        neg = d.peaks_negative if d.peaks_negative is not None else -d.peaks[:, :, ::-1]
        rec["tuning"] = {  # peak of each load over time per scanned gradient, both gust signs
            n: {
                "up_max": d.peaks[:, i, 0].tolist(),
                "up_min": d.peaks[:, i, 1].tolist(),
                "down_max": neg[:, i, 0].tolist(),
                "down_min": neg[:, i, 1].tolist(),
            }
            for i, n in enumerate(d.loads)
            if n in keep
        }
        rec["amplitudes"] = [float(a) for a in d.amplitudes]
        if turb is not None:
            rec["covariance"] = {
                "outputs": list(turb.outputs),
                "matrix": np.asarray(turb.covariance).tolist(),
            }
        keys = {}
        for (h, sign), (t, gust, y) in d.histories.items():
            key = f"p{index}_{loop}_H{h:.6g}_{'up' if sign > 0 else 'down'}"
            arrays[key + "_t"], arrays[key + "_gust"], arrays[key + "_y"] = t, gust, y
            keys[f"{h!r} {sign}"] = key
        rec["history_loads"] = list(d.loads)
        rec["histories"] = {
            name: {s: keys[f"{e.side(s)[1]!r} {e.side(s)[3]}"] for s in ("max", "min")}
            for name, e in d.extremes.items()
            if name in keep
        }
        records.append(rec)
    return records, arrays


def totals(v: dict, turb: float) -> dict:
    """The 1 g load and the total limit loads ``1 g + max`` and ``1 g + min`` of one load
    (NaN without a 1 g trim): the discrete extremes and ``+- U_sigma A_bar``."""
    one_g = v.get("one_g", np.nan)
    up = np.nanmax([v["max"], turb])
    down = np.nanmin([v["min"], -turb])
    return {"one_g": one_g, "total_max": one_g + up, "total_min": one_g + down}
