"""Run a limit-cycle study: every march in this process or on Dask, with a progress bar, and
the describing-function prediction (of the open loop, or of the sampled loop with its
controller)."""

from __future__ import annotations

import time

import numpy as np

from ...errors import InputError, check_int
from .plausibility import plausibility_notes
from .result import LCOResult
from .study import LCOSetup, LCOSweep, march_task

__all__ = ["run_lco"]


def run_lco(
    setup: LCOSetup,
    sweep: LCOSweep,
    *,
    workers: int = 0,
    scheduler: str | None = None,
    progress: bool = False,
    timeout: float = 60.0,
    describing: bool = True,
) -> LCOResult:
    """March every point and sweep of ``sweep`` and judge each.

    Parameters
    ----------
    setup : LCOSetup
    sweep : LCOSweep
    workers : int
        0: in this process; N > 0: a local Dask cluster of N worker processes.
    scheduler : str, optional
        Address of a running Dask scheduler (overrides ``workers``).
    progress : bool
        A progress bar over the marches on stderr.
    timeout : float
        Time allowed for local workers to start [s].
    describing : bool
        Add the describing-function branches (gaps centred at zero; with a controller, of its
        sampled loop).

    Returns
    -------
    LCOResult
    """
    from tqdm import tqdm

    if not isinstance(setup, LCOSetup):
        raise InputError(f"setup = {setup!r}: expected an LCOSetup")
    if not isinstance(sweep, LCOSweep):
        raise InputError(f"sweep = {sweep!r}: expected an LCOSweep")
    workers = check_int("workers", workers, lo=0, hi=256)
    sweep.steps(sweep.dt if setup.controller is None else float(setup.controller.dt))
    t0 = time.perf_counter()
    tasks = sweep.tasks()
    marches = sum(len(t[1]) for t in tasks)
    bar = tqdm(total=len(tasks), desc=setup.name, unit="task", disable=not progress)
    shared = (setup, sweep)
    with bar:
        if scheduler is None and workers == 0:
            done = []
            for task in tasks:
                done.append(march_task(shared, task))
                bar.update(1)
        else:
            from ..dask_runner import map_tasks

            done = map_tasks(
                march_task, shared, tasks, workers=workers, scheduler=scheduler,
                timeout=timeout, bar=bar, what=f"lco-{setup.name}",
            )  # fmt: skip
    rows = [r for rs in done for r in rs]
    notes = plausibility_notes(setup, sweep.extra.get("hinges_source", "hinges"))
    branches = None
    if describing:
        branches, note = _describing(setup, sweep)
        if note:
            notes.append(note)
        if branches is not None:  # what its grids did not resolve
            notes += [f"describing function: {n}" for n in branches.notes]
    settings = {
        "name": setup.name,
        "density": setup.density,
        "elements": list(setup.elements.names),
        "laws": [law.describe() for law in setup.elements.laws],
        "stiffness": setup.elements.stiffness.tolist(),
        "reference": setup.reference,
        "gap": setup.gap,
        "closed_loop": setup.controller is not None,
        "controller": _describe(setup.controller),
        "speeds": [float(v) for v in sweep.speeds],
        "amplitudes": [float(a) for a in sweep.amplitudes],
        "duration": sweep.duration,
        "dt": sweep.dt if setup.controller is None else float(setup.controller.dt),
        "settle": sweep.settle,
        "continuation": sweep.continuation,
        "marches": marches,
        "elapsed": time.perf_counter() - t0,
        "workers": workers if scheduler is None else scheduler,
        "notes": notes,
    } | dict(sweep.extra)
    return LCOResult(rows, settings, branches)


def _describe(controller) -> str:
    if controller is None:
        return "open loop"
    return str(getattr(controller, "name", None) or type(controller).__name__)


def _describing(setup: LCOSetup, sweep: LCOSweep):
    """The describing-function branches of the open loop, or of the sampled loop with
    ``setup.controller`` (:func:`~aeroservo.design.hinge_describing.loop_describing_branches`),
    or None and a note why not."""
    from ...stability.describing_function import describing_branches

    if any(getattr(law, "offset", 0.0) != 0.0 for law in setup.elements.laws):
        return None, "describing function: not computed for a gap that is not centred at zero"
    v = np.asarray(sweep.speeds, dtype=float)
    if setup.controller is not None:
        if setup.loop is None:
            return None, "describing function: not computed for a controller without a loop"
        from ...design.hinge_describing import loop_describing_branches

        # 32 amplitudes x 40 speeds of a ~100-state loop: about 15 s on one core
        speeds = np.linspace(0.8 * v.min(), 1.2 * v.max(), 40)
        try:
            b = loop_describing_branches(
                setup.loop, setup.hinges, setup.controller, _loop_amplitudes(setup, sweep), speeds
            )
        except (InputError, ArithmeticError, np.linalg.LinAlgError) as exc:
            return None, f"describing function: not computed ({exc})"
        return b, "describing function: of the sampled loop, actuator limits inactive"
    model = setup.loop.model if setup.loop is not None else setup.model
    system = model.system(setup.density)
    elements = setup.elements
    if getattr(model, "dlm", None) is not None:  # its systems are on the aerodynamic basis
        elements = elements.project(model.dlm.basis)
    small = system.n_states <= 40  # a section: fine grids; a wing: coarser (eig per speed)
    amps = _amplitudes(setup, sweep, 120 if small else 36)
    lo, hi = (0.5, 1.5) if small else (0.8, 1.2)
    speeds = np.linspace(lo * v.min(), hi * v.max(), 240 if small else 80)
    try:
        return describing_branches(system, elements, amps, speeds=speeds), None
    except (InputError, ArithmeticError) as exc:
        return None, f"describing function: not computed ({exc})"


def _amplitudes(setup: LCOSetup, sweep: LCOSweep, n: int) -> np.ndarray:
    """``n`` amplitudes [rad]: dense where limit cycles are (A/gap from 0.5 to 2), geometric
    beyond, up to 4 times the largest initial rotation."""
    gap = setup.gap
    top = max(sweep.amplitudes) * 4.0
    if not gap:
        return np.geomspace(top * 1e-3, top, n)
    ratio = np.concatenate(
        [
            0.5 + np.geomspace(1e-4, 0.05, n // 6, endpoint=False),
            np.linspace(0.55, 2.0, 2 * n // 3, endpoint=False),
            np.geomspace(2.0, max(top / gap, 4.0), n // 6),
        ]
    )
    return gap * ratio


def _loop_amplitudes(setup: LCOSetup, sweep: LCOSweep, n: int = 32) -> np.ndarray:
    """``n`` amplitudes [rad] evenly spaced in the equivalent stiffness of a gap (``N/k`` from
    1e-3 to its value at 4 times the largest initial rotation, at least 4 gaps): the loop's
    stability depends on ``N``, and its limit cycles near the gap edge, where ``N`` changes
    fastest (the buzz of a loop designed for stiff actuators), are resolved."""
    from ...structure.hinge_laws import freeplay_gain

    gap = setup.gap
    if not gap:
        return _amplitudes(setup, sweep, n)
    top = max(max(sweep.amplitudes) * 4.0 / gap, 4.0)
    table = 0.5 + np.geomspace(1e-6, top - 0.5, 4000)  # A / gap
    gain = freeplay_gain(table, 1.0)
    return gap * np.interp(np.linspace(1e-3, gain[-1], n), gain, table)
