"""The teaching notebooks in ``notebooks/``: stored clean, and they run top to bottom.

(a) Every stored notebook is valid and has no outputs and no execution counts (outputs are not
    versioned; run the notebook to see them).
(b) Every notebook executes in a fresh kernel of *this* interpreter with nbclient, with
    ``notebooks/`` as the working directory, without error (slow: about half a minute each).
"""

from __future__ import annotations

import json
import os
import shutil
import sys
import time
from pathlib import Path

import nbformat
import pytest

NOTEBOOKS_DIR = Path(__file__).resolve().parent.parent / "notebooks"
NOTEBOOKS = sorted(NOTEBOOKS_DIR.glob("*.ipynb"))
EXPECTED = {
    "01_goland_flutter.ipynb",
    "02_lqr_lqg_design.ipynb",
    "03_mpc_vs_saturated_lqr.ipynb",
    "04_trade_study.ipynb",
    "05_flutter_clearance.ipynb",
    "06_sensitivities_and_tailoring.ipynb",
    "07_bring_your_own_controller.ipynb",
    "08_gust_loads.ipynb",
    "09_freeplay_lco.ipynb",
}
KERNEL = "python3"


def test_expected_notebooks_present():
    assert EXPECTED <= {p.name for p in NOTEBOOKS}


@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_stored_without_outputs(path):
    nb = nbformat.read(path, as_version=4)
    nbformat.validate(nb)
    assert nb.metadata.kernelspec.name == KERNEL
    for i, cell in enumerate(nb.cells):
        if cell.cell_type != "code":
            continue
        assert cell.outputs == [], f"{path.name}: cell {i} has stored outputs"
        assert cell.execution_count is None, f"{path.name}: cell {i} has an execution count"


def _runs_this_python(argv0: str) -> bool:
    """Whether a kernelspec's ``argv[0]`` starts the interpreter running the tests.

    jupyter_client replaces ``python``, ``python3`` and ``python3.X`` by ``sys.executable``;
    anything else must be this interpreter's path (symlinks are not resolved: a virtual
    environment's python is a symlink to the base interpreter, which lacks the packages).
    """
    major, minor = sys.version_info[:2]
    if argv0 in {"python", f"python{major}", f"python{major}.{minor}"}:
        return True
    found = shutil.which(argv0) or argv0
    return os.path.abspath(found) == os.path.abspath(sys.executable)


@pytest.fixture(scope="module")
def kernel_name(tmp_path_factory):
    """The ``python3`` kernel, made to run ``sys.executable``.

    If the installed ``python3`` kernelspec would start another interpreter, a temporary one
    pointing at ``sys.executable`` is put first on ``JUPYTER_PATH``. BLAS pools are limited to
    one thread (small matrices; the notebooks do the same unless told otherwise).
    """
    from jupyter_client.kernelspec import KernelSpecManager, NoSuchKernel

    with pytest.MonkeyPatch.context() as mp:
        for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
            mp.setenv(var, "1")
        try:
            argv = KernelSpecManager().get_kernel_spec(KERNEL).argv
        except NoSuchKernel:
            argv = []
        if not (argv and _runs_this_python(argv[0])):
            root = tmp_path_factory.mktemp("jupyter")
            spec_dir = root / "kernels" / KERNEL
            spec_dir.mkdir(parents=True)
            spec = {
                "argv": [sys.executable, "-m", "ipykernel_launcher", "-f", "{connection_file}"],
                "display_name": "Python 3 (tests)",
                "language": "python",
            }
            (spec_dir / "kernel.json").write_text(json.dumps(spec), encoding="utf-8")
            mp.setenv(
                "JUPYTER_PATH", os.pathsep.join([str(root), os.environ.get("JUPYTER_PATH", "")])
            )
            argv = KernelSpecManager().get_kernel_spec(KERNEL).argv
        assert _runs_this_python(argv[0]), argv
        yield KERNEL


@pytest.mark.slow
@pytest.mark.parametrize("path", NOTEBOOKS, ids=lambda p: p.stem)
def test_notebook_runs(path, kernel_name):
    import nbclient

    nb = nbformat.read(path, as_version=4)
    client = nbclient.NotebookClient(
        nb,
        timeout=600,
        startup_timeout=120,
        kernel_name=kernel_name,
        resources={"metadata": {"path": str(NOTEBOOKS_DIR)}},
    )
    t0 = time.perf_counter()
    client.execute()  # raises CellExecutionError on the first failing cell
    elapsed = time.perf_counter() - t0
    errors = [
        o for c in nb.cells if c.cell_type == "code" for o in c.outputs if o.output_type == "error"
    ]
    assert not errors
    print(f"{path.name}: executed in {elapsed:.1f} s")
