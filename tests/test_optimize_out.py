"""``aeroservo optimize FILE --out DIR`` (issue 25, item 9): the optimum as a wing file that
``aeroservo flutter`` runs again, the iterate history (CSV) and the convergence plot, written
as a set (a failed run leaves no file); without ``--out`` nothing is written.

The two shipped cases run in about a second each. The wing file must give back the optimum's
flutter speed: it describes the same model bit for bit (numbers written with ``repr``, the
density, elements and damping of the optimization file in ``[analysis]`` and ``[damping]``),
so the two analyses can differ only by the summation order of a threaded BLAS (rel 1e-12).
"""

from __future__ import annotations

import csv
import json

import pytest
from conftest import ROOT

from aeroservo.cli import main
from aeroservo.studies.optimize import ACTIVE

TORSION = ROOT / "scenarios" / "optimize_goland_torsion.toml"
BALANCE = ROOT / "scenarios" / "optimize_goland_mass_balance.toml"  # with damping g = 0.02


def _run_json(capsys, argv: list[str]) -> dict:
    assert main(argv) == 0
    return json.loads(capsys.readouterr().out)


@pytest.mark.parametrize("case", [TORSION, BALANCE], ids=["torsion", "mass_balance"])
@pytest.mark.slow
def test_out_writes_a_wing_that_flutters_at_the_optimum(tmp_path, capsys, case):
    out = tmp_path / "new" / "folder"  # created, parents too
    r = _run_json(capsys, ["optimize", str(case), "--out", str(out), "--json"])
    stem = case.stem
    assert r["files"] == {
        "wing": str(out / f"{stem}_wing.toml"),
        "history": str(out / f"{stem}_history.csv"),
        "convergence": str(out / f"{stem}_convergence.png"),
    }
    assert sorted(p.name for p in out.iterdir()) == sorted(
        f"{stem}_{k}" for k in ("wing.toml", "history.csv", "convergence.png")
    )
    again = _run_json(capsys, ["flutter", r["files"]["wing"], "--json"])
    assert again["flutter_speed"] == pytest.approx(r["flutter_speed"], rel=1e-12)
    assert again["divergence_speed"] == pytest.approx(r["divergence_speed"], rel=1e-12)
    assert again["density"] == 1.225 and again["n_elements"] == 10
    assert (out / f"{stem}_convergence.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_history_csv(tmp_path, capsys):
    """One row per SLSQP iterate from the start to the optimum, units in the header, the
    constraint's ``V_f / bound - 1`` going to zero (active)."""
    r = _run_json(capsys, ["optimize", str(TORSION), "--out", str(tmp_path), "--json"])
    with open(r["files"]["history"], newline="", encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0]) == [
        "iteration",
        "segments[0].GJ [N m^2]",
        "segments[1].GJ [N m^2]",
        "objective",
        "flutter_speed [m/s]",
        "divergence_speed [m/s]",
        "flutter_speed_min margin [-]",
        "designs_analysed",
        "flutter_boundaries",
    ]
    assert [int(row["iteration"]) for row in rows] == list(range(len(rows)))
    assert len(rows) >= 3
    first, last = rows[0], rows[-1]
    for name in ("segments[0].GJ", "segments[1].GJ"):
        assert float(first[f"{name} [N m^2]"]) == r["start"][name]
        assert float(last[f"{name} [N m^2]"]) == r["variables"][name]
    assert float(last["objective"]) == pytest.approx(r["objective"], rel=1e-12)
    v_first, v_last = float(first["flutter_speed [m/s]"]), float(last["flutter_speed [m/s]"])
    assert float(first["flutter_speed_min margin [-]"]) == pytest.approx(v_first / 149.5 - 1)
    assert abs(float(last["flutter_speed_min margin [-]"])) < ACTIVE
    assert v_last == pytest.approx(r["flutter_speed"], rel=1e-6)  # last iterate vs fresh check
    counts = [int(row["flutter_boundaries"]) for row in rows]
    assert counts == sorted(counts) and counts[-1] <= r["n_boundaries"]


def test_a_failed_write_leaves_no_file(tmp_path, capsys, monkeypatch):
    """The convergence plot fails to save (written last): neither the wing file nor the
    history is left behind, nor the folder the run created; one error line naming the file."""
    import aeroservo.atomic

    def broken(fig, path, **kw):
        def write(p):
            raise OSError(28, "No space left on device", str(p))

        return write

    monkeypatch.setattr(aeroservo.atomic, "figure_writer", broken)
    out = tmp_path / "res"
    assert main(["optimize", str(TORSION), "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert "optimize_goland_torsion_convergence.png" in err and len(err.splitlines()) == 1
    assert not out.exists()
    existing = tmp_path / "kept"
    existing.mkdir()
    assert main(["optimize", str(TORSION), "--out", str(existing)]) == 2
    assert list(existing.iterdir()) == []


def test_without_out_nothing_is_written(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    r = _run_json(capsys, ["optimize", str(TORSION), "--json"])
    assert "files" not in r and r["success"]
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize(
    "argv_tail,fragment",
    [
        (["--out", "FILE"], "is a file, expected a folder"),
        (["--out", " "], "give an output folder"),
    ],
)
def test_bad_out(tmp_path, capsys, argv_tail, fragment):
    (tmp_path / "FILE").write_text("x")
    tail = [str(tmp_path / a) if a == "FILE" else a for a in argv_tail]
    assert main(["optimize", str(TORSION), *tail]) == 2
    err = capsys.readouterr().err
    assert fragment in err and len(err.splitlines()) == 1


def test_codesign_refuses_out(tmp_path, capsys):
    """A co-design file's optimum is a trade case, not a wing: refused before it runs."""
    codesign = ROOT / "scenarios" / "codesign_aileron_lqr.toml"
    assert main(["optimize", str(codesign), "--out", str(tmp_path / "x")]) == 2
    err = capsys.readouterr().err
    assert "co-design" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "x").exists()
