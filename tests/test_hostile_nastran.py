"""Hostile inputs on the Nastran import (issue 40 item 2): ``aeroservo import nastran``.

The rule: exit 2 with one line naming the file at fault and, where there is one, the card, its
id and the field (exit 1 for a numerical failure); no traceback; nothing left behind in the
working folder (no ``pyNastran_crash.bdf``, no partial output) and no input overwritten; no
hang and bounded memory: a FIFO, a device or a huge file is refused before it is opened or read.

Decks are the shipped sample (``examples/nastran/swept_wing_d10023a.bdf``, inch-pound-second)
edited one card at a time, and small stick models written here. Every case runs the command
in-process with its streams captured, in ``tmp_path`` as the working folder; special files
(the FIFO, ``/dev/zero``, the sparse 1 GiB file) are guarded: opening one raises at once, so a
regression fails instead of hanging.
"""

from __future__ import annotations

import builtins
import contextlib
import io
import os
import re
from pathlib import Path

import pytest

pytest.importorskip(
    "pyNastran",
    reason="pyNastran is not installed (optional: pip install 'aeroservo[nastran]'; .ci/run "
    "installs it): the hostile Nastran decks are not tested",
)

from aeroservo.cli import main  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
SAMPLE = (ROOT / "examples" / "nastran" / "swept_wing_d10023a.bdf").read_text()
MAT = "MAT1    1       10.4+6  3.9+6           2.61-4                                  \n"
GIB = 1024**3


def edit(old: str, new: str, text: str = SAMPLE) -> str:
    """The sample deck with one piece of text replaced (it must be there)."""
    assert old in text, old
    return text.replace(old, new, 1)


def add(cards: str) -> str:
    """The sample deck with cards added before ENDDATA."""
    return edit("ENDDATA", cards + "ENDDATA")


def real(x: float) -> str:
    """A Nastran real field (with a decimal point, as a real field needs)."""
    text = f"{x:.8g}"
    return text if "." in text or "e" in text else text + "."


def stick(scale: float = 1.0, mass_scale: float = 1.0, n: int = 4, extra: str = "") -> str:
    """A cantilever of ``n`` CBARs along +Y, 8 m long in SI (no RHO: its mass is NSM; no aero
    cards), in units of length ``scale`` m and mass ``mass_scale`` kg (mm-t-s: 1e-3, 1e3)."""
    L, M = 1.0 / scale, 1.0 / mass_scale  # deck units per metre, per kilogram
    stress = M / L  # deck stress units per pascal (the stress unit is mass / length / s^2)
    lines = [f"GRID,{i + 1},,0.,{real(8.0 * i / n * L)},0." for i in range(n + 1)]
    lines += [f"CBAR,{i + 1},1,{i + 1},{i + 2},0.,0.,1." for i in range(n)]
    values = (0.01 * L**2, 1e-4 * L**4, 1e-3 * L**4, 2e-4 * L**4)
    lines += [
        f"PBAR,1,1,{','.join(real(v) for v in values)},{real(50.0 * M / L)}",
        f"MAT1,1,{real(7e10 * stress)},{real(2.6e10 * stress)}",
        "SPC1,1,123456,1",
    ]
    return "\n".join(lines) + "\n" + extra


INERTIA = "inertia = 5.0\n"  # the stick's pitch inertia per length [kg m] (it has no RHO)
STICK = ["--out", "w.toml", "--chord", "1", "--elastic-axis", "0", "--companion", "c.toml"]
IN = ["--out", "w.toml", "--units", "in-lbf-s"]
FIFO, SPARSE, FOLDER = object(), object(), object()

# id: (files {name: text | bytes | FIFO | SPARSE | FOLDER | ("link"|"hard", target)}, deck,
#      options, exit code, what stderr must say (regex), the file it must name)
CASES = {
    # the output would overwrite an input
    "out-is-deck": ({"d.bdf": SAMPLE}, "d.bdf", ["--out", "d.bdf"], 2, r"--out = d.bdf: that is the deck", "d.bdf"),
    "out-is-deck-spelt-otherwise": ({"d.bdf": SAMPLE, "sub": FOLDER}, "d.bdf", ["--out", "./sub/../d.bdf"], 2, r"that is the deck", "d.bdf"),
    "out-is-link-to-deck": ({"d.bdf": SAMPLE, "w.toml": ("link", "d.bdf")}, "d.bdf", IN, 2, r"that is the deck", "w.toml"),
    "out-is-hard-link-to-deck": ({"d.bdf": SAMPLE, "w.toml": ("hard", "d.bdf")}, "d.bdf", IN, 2, r"that is the deck", "w.toml"),
    "out-is-include": ({"d.bdf": edit(MAT, "INCLUDE 'mat.bdf'\n"), "mat.bdf": MAT}, "d.bdf", ["--out", "mat.bdf"], 2, r"that is a file the deck INCLUDEs", "mat.bdf"),
    "scenario-is-include": ({"d.bdf": edit(MAT, "INCLUDE 'w_flutter.toml'\n"), "w_flutter.toml": MAT}, "d.bdf", IN, 2, r"the flutter scenario = w_flutter.toml: that is a file the deck INCLUDEs", "w_flutter.toml"),
    "out-is-companion": ({"d.bdf": SAMPLE, "c.toml": "a = 0.0\n"}, "d.bdf", ["--out", "c.toml", "--companion", "c.toml"], 2, r"that is the companion table", "c.toml"),
    # what the deck is: type and size checked before it is opened
    "deck-fifo": ({"d.bdf": FIFO}, "d.bdf", IN, 2, r"not a regular file", "d.bdf"),
    "deck-dev-zero": ({}, "/dev/zero", IN, 2, r"not a regular file", "/dev/zero"),
    "deck-link-to-dev-zero": ({"d.bdf": ("link", "/dev/zero")}, "d.bdf", IN, 2, r"not a regular file", "d.bdf"),
    "deck-folder": ({"d.bdf": FOLDER}, "d.bdf", IN, 2, r"is a folder", "d.bdf"),
    "deck-missing": ({}, "d.bdf", IN, 2, r"no such file", "d.bdf"),
    "deck-1-GiB": ({"d.bdf": SPARSE}, "d.bdf", IN, 2, r"1\.02e\+03 MiB: more than the 8 MiB", "d.bdf"),
    "deck-binary": ({"d.bdf": bytes(range(256)) * 4}, "d.bdf", IN, 2, r"a NUL byte on line 1 \(byte 0\): a binary file", "d.bdf"),
    "deck-utf16": ({"d.bdf": SAMPLE.encode("utf-16")}, "d.bdf", IN, 2, r"UTF-16 or UTF-32 text", "d.bdf"),
    "deck-empty": ({"d.bdf": b""}, "d.bdf", IN, 2, r"no CBAR or CBEAM element", "d.bdf"),
    # INCLUDE files: found, checked and bounded like the deck; nothing left behind
    "include-missing": ({"d.bdf": edit(MAT, "INCLUDE 'mat.bdf'\n")}, "d.bdf", IN, 2, r"d\.bdf: INCLUDE 'mat\.bdf' \(line 80\): \S+mat\.bdf does not exist", "d.bdf"),
    "include-fifo": ({"d.bdf": edit(MAT, "INCLUDE 'p.bdf'\n"), "p.bdf": FIFO}, "d.bdf", IN, 2, r"INCLUDE 'p\.bdf' \(line 80\): \S+p\.bdf: not a regular file", "d.bdf"),
    "include-dev-zero": ({"d.bdf": edit(MAT, "INCLUDE '/dev/zero'\n")}, "d.bdf", IN, 2, r"INCLUDE '/dev/zero' \(line 80\): /dev/zero: not a regular file", "d.bdf"),
    "include-folder": ({"d.bdf": edit(MAT, "INCLUDE 'sub'\n"), "sub": FOLDER}, "d.bdf", IN, 2, r"INCLUDE 'sub' \(line 80\): \S+sub: is a folder", "d.bdf"),
    "include-1-GiB": ({"d.bdf": edit(MAT, "INCLUDE 'big.bdf'\n"), "big.bdf": SPARSE}, "d.bdf", IN, 2, r"INCLUDE 'big\.bdf' \(line 80\): \S+big\.bdf: 1\.02e\+03 MiB with the files before it", "d.bdf"),
    "include-itself": ({"d.bdf": edit(MAT, MAT + "INCLUDE 'd.bdf'\n")}, "d.bdf", IN, 2, r"INCLUDE 'd\.bdf' \(line 81\): \S+d\.bdf is read already", "d.bdf"),
    "include-twice": ({"d.bdf": edit(MAT, "INCLUDE 'mat.bdf'\nINCLUDE 'mat.bdf'\n"), "mat.bdf": MAT}, "d.bdf", IN, 2, r"INCLUDE 'mat\.bdf' \(line 81\): \S+mat\.bdf is read already", "d.bdf"),
    "include-binary": ({"d.bdf": edit(MAT, "INCLUDE 'mat.bdf'\n"), "mat.bdf": b"\x00\x01"}, "d.bdf", IN, 2, r"INCLUDE 'mat\.bdf' \(line 80\): a NUL byte", "d.bdf"),
    "nan-in-include": ({"d.bdf": edit(MAT, "INCLUDE 'mat.bdf'\n"), "mat.bdf": "MAT1    1       nan     3.9+6           2.61-4\n"}, "d.bdf", IN, 2, r"MAT1 1: E \(field 3\) = nan \(line 1 of mat\.bdf\): not a finite number", "d.bdf"),
    # a byte that is not ASCII in a field (in a comment it is read: test_accepted below)
    "latin1-byte-in-field": ({"d.bdf": edit("GRID    6  ", "GRID    6\xe9 ").encode("latin-1")}, "d.bdf", IN, 2, r"GRID: nid = '6\xe9' \(field #1\) on card must be an integer", "d.bdf"),
    # numbers that are not finite, in every field format
    "nan-grid-coordinate": ({"d.bdf": edit("GRID    6               0.0     2.86 ", "GRID    6               0.0     nan  ")}, "d.bdf", IN, 2, r"d\.bdf: GRID 6: X2 \(field 5\) = nan \(line 74\): not a finite number", "d.bdf"),
    "overflow-grid-coordinate": ({"d.bdf": edit("GRID    6               0.0     2.86    ", "GRID    6               0.0     1.+400  ")}, "d.bdf", IN, 2, r"GRID 6: X2 \(field 5\) = 1\.\+400 \(line 74\)", "d.bdf"),
    "inf-free-field": ({"d.bdf": edit("GRID    6               0.0     2.86    0.0", "GRID,6,,0.0,2.86,-inf")}, "d.bdf", IN, 2, r"GRID 6: X3 \(field 6\) = -inf \(line 74\)", "d.bdf"),
    "nan-large-field": ({"d.bdf": edit("GRID    6               0.0     2.86    0.0", "GRID*   6                               0.0             2.86\n*       NaN")}, "d.bdf", IN, 2, r"GRID 6: X3 \(field 6\) = NaN \(line 75\): not a finite number", "d.bdf"),
    "nan-conm2-mass": ({"d.bdf": add("CONM2   99      6               nan\n")}, "d.bdf", IN, 2, r"CONM2 99: M \(field 5\) = nan \(line 91\)", "d.bdf"),
    "nan-flfact": ({"d.bdf": edit("4000.   5000.", "4000.   NAN  ")}, "d.bdf", IN, 2, r"FLFACT 4: field 4 = NAN \(line 66\)", "d.bdf"),
    "nan-wtmass": ({"d.bdf": add("PARAM   WTMASS  nan\n")}, "d.bdf", IN, 2, r"PARAM WTMASS: V1 \(field 3\) = nan", "d.bdf"),
    "inf-aero-rhoref": ({"d.bdf": edit("1.145-7", "1.+999 ")}, "d.bdf", IN, 2, r"AERO: RHOREF \(field 5\) = 1\.\+999", "d.bdf"),
    # values out of range, named by card and field
    "negative-density": ({"d.bdf": edit("2.61-4  ", "-2.61-4 ")}, "d.bdf", IN, 2, r"d\.bdf: MAT1 1: RHO = -0\.000261: a density must be >= 0", "d.bdf"),
    "wtmass-zero": ({"d.bdf": add("PARAM   WTMASS  0.0\n")}, "d.bdf", IN, 2, r"d\.bdf: PARAM WTMASS = 0: must be > 0", "d.bdf"),
    "wtmass-negative": ({"d.bdf": add("PARAM   WTMASS  -1.0\n")}, "d.bdf", IN, 2, r"PARAM WTMASS = -1: must be > 0", "d.bdf"),
    "conm2-1e9-kg": ({"d.bdf": add("CONM2   99      6               1.+9\n")}, "d.bdf", IN, 2, r"weighs 1\.751e\+11 kg \(most of it CONM2 99 at GRID 6\)", "d.bdf"),
    "conm2-2e6-kg-on-a-plausible-wing": ({"d.bdf": stick(extra="CONM2,99,3,,2.e6\n"), "c.toml": INERTIA}, "d.bdf", STICK, 2, r"d\.bdf: CONM2 99 at GRID 3: mass = 2e\+06: allowed range is \[0, 1e\+06\]", "d.bdf"),
    "nspan-nchord-huge": ({"d.bdf": edit("CAERO1  101     1       1       6       4 ", "CAERO1  101     1       1       9999999 9999999")}, "d.bdf", IN, 2, r"CAERO1 101: NSPAN = 9999999, NCHORD = 9999999: 99999980000001 boxes", "d.bdf"),
    # cards given twice
    "duplicate-grid": ({"d.bdf": add("GRID    3               0.0     1.5     0.0\n")}, "d.bdf", IN, 2, r"GRID 3 is given twice, with different fields \('GRID 3 0\. 1\.144 0\.' and 'GRID 3 0\. 1\.5 0\.'\)", "d.bdf"),
    "duplicate-mat1": ({"d.bdf": add("MAT1    1       10.4+6  3.9+6           2.7-4\n")}, "d.bdf", IN, 2, r"MAT1 1 is given twice, with different fields", "d.bdf"),
    "duplicate-cbar": ({"d.bdf": add("CBAR    1       1       5       6       0.0     0.0     1.\n")}, "d.bdf", IN, 2, r"CBAR 1 is given twice, with different fields", "d.bdf"),
    # ranges pyNastran would list id by id (gigabytes, minutes)
    "set1-thru-huge": ({"d.bdf": edit("SET1    100     1       THRU    11 ", "SET1    100     1       THRU    90000000")}, "d.bdf", IN, 2, r"SET1 100: 1 THRU 90000000 \(line 87\): 89999999 values", "d.bdf"),
    "spc1-thru-huge": ({"d.bdf": edit("SPC1    1       345     1 ", "SPC1    1       345     1       THRU    90000000")}, "d.bdf", IN, 2, r"SPC1 1: 1 THRU 90000000 \(line 88\)", "d.bdf"),
    "case-control-set-huge": ({"d.bdf": edit("     SPC = 1", "SET 7 = 1 THRU 900000000\n     SPC = 1")}, "d.bdf", IN, 2, r"case control SET: 1 THRU 900000000 \(line 22\)", "d.bdf"),
    "flfact-thru-nf-huge": ({"d.bdf": edit("FLFACT  1       .967    ", "FLFACT  1       .967    THRU    .968    90000000")}, "d.bdf", IN, 2, r"FLFACT 1: NF = 90000000 \(line 63\)", "d.bdf"),
    "too-many-elements": ({"d.bdf": stick(n=10_001), "c.toml": INERTIA}, "d.bdf", STICK, 2, r"10001 beam elements, more than the 10000", "d.bdf"),
    # units that make the wing implausible
    "mm-t-s-read-as-si": ({"d.bdf": stick(1e-3, 1e3), "c.toml": INERTIA}, "d.bdf", STICK, 2, r"the beam line is 8000 m long and weighs 0\.4 kg .*in si units: longer than the 200 m of any wing; the deck looks like mm-t-s units: give --units mm-t-s", "d.bdf"),
    "si-read-as-mm-t-s": ({"d.bdf": stick(), "c.toml": INERTIA}, "d.bdf", [*STICK, "--units", "mm-t-s"], 2, r"the beam line is 0\.008 m long and weighs 4e\+05 kg .*mass / length\^3 = 7\.81e\+11 kg/m\^3, outside .*give --units si", "d.bdf"),
    "sample-read-as-si": ({"d.bdf": SAMPLE}, "d.bdf", ["--out", "w.toml"], 2, r"AERO RHOREF x FLFACT 1: .*give --units in-lbf-s", "d.bdf"),
    # the companion table
    "companion-section-beyond-span": ({"d.bdf": SAMPLE, "c.toml": "[[sections]]\nstart = 10.0\nend = 20.0\nsemichord = 0.1\n"}, "d.bdf", [*IN, "--companion", "c.toml"], 2, r"c\.toml: sections\[0\]\.end = 20 m: beyond the tip, the beam line is 0\.145288 m long", "c.toml"),
    "companion-section-in-inches": ({"d.bdf": SAMPLE, "c.toml": "[[sections]]\nstart = 0.0\nend = 5.72\nsemichord = 0.02\n"}, "d.bdf", [*IN, "--companion", "c.toml"], 2, r"sections\[0\]\.end = 5\.72 m: beyond the tip, .*in-lbf-s converted to SI; the table is in metres", "c.toml"),
    "companion-section-between-midpoints": ({"d.bdf": SAMPLE, "c.toml": "[[sections]]\nstart = 0.0\nend = 0.001\nsemichord = 0.02\n"}, "d.bdf", [*IN, "--companion", "c.toml"], 2, r"sections\[0\] \(0 to 0\.001 m\) holds no element's midpoint", "c.toml"),
    "companion-fifo": ({"d.bdf": SAMPLE, "c.toml": FIFO}, "d.bdf", [*IN, "--companion", "c.toml"], 2, r"c\.toml: not a regular file", "c.toml"),
}  # fmt: skip


def _make(tmp_path: Path, files: dict) -> set[str]:
    """Write the case's files; the paths that must never be opened (the special ones)."""
    guarded = set()
    for name, content in files.items():
        path = tmp_path / name
        if content is FIFO:
            os.mkfifo(path)
            guarded.add(str(path))
        elif content is SPARSE:
            with open(path, "wb") as fh:
                fh.truncate(GIB)  # 1 GiB of nothing on disk
            guarded.add(str(path))
        elif content is FOLDER:
            path.mkdir()
        elif isinstance(content, tuple):
            kind, target = content
            (os.symlink if kind == "link" else os.link)(target, path)
        else:
            path.write_bytes(content if isinstance(content, bytes) else content.encode())
    return guarded | {"/dev/zero"}


def _guard(monkeypatch, guarded: set[str]) -> None:
    """Opening a guarded file raises at once (a regression fails instead of hanging)."""

    def wrap(real):
        def opener(file, *args, **kwargs):
            if isinstance(file, (str, os.PathLike)) and os.path.realpath(file) in guarded:
                raise AssertionError(f"the import opened {file}")
            return real(file, *args, **kwargs)

        return opener

    guarded = {os.path.realpath(p) for p in guarded}
    monkeypatch.setattr(builtins, "open", wrap(builtins.open))
    monkeypatch.setattr(io, "open", wrap(io.open))
    monkeypatch.setattr(os, "open", wrap(os.open))


def _snapshot(folder: Path) -> dict[str, bytes | None]:
    """Every entry of a folder with the content of its regular files (None for the others)."""
    out = {}
    for p in folder.iterdir():
        regular = p.is_file() and not p.is_symlink() and p.stat().st_size < 2**20
        out[p.name] = p.read_bytes() if regular else None
    return out


def _run(argv: list[str]) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main(argv)
    return code, out.getvalue(), err.getvalue()


@pytest.mark.parametrize("case", list(CASES), ids=list(CASES))
def test_hostile(case, tmp_path, monkeypatch):
    """Exit code, one line naming the file (and the card, field, value where there is one), no
    traceback, the working folder as it was (no crash file, no output, inputs unchanged)."""
    files, deck, options, code, says, names = CASES[case]
    monkeypatch.chdir(tmp_path)
    _guard(monkeypatch, _make(tmp_path, files))
    before = _snapshot(tmp_path)
    got, out, err = _run(["import", "nastran", deck, *options])
    lines = err.strip().splitlines()
    assert got == code, err
    assert len(lines) == 1, err
    assert "Traceback" not in err and out == ""
    assert lines[0].startswith("aeroservo: error: ") and names in lines[0], lines[0]
    assert re.search(says, lines[0]), lines[0]
    assert _snapshot(tmp_path) == before  # nothing written, nothing left, nothing changed


ACCEPTED = {  # the same wing as the sample's
    "latin1-comment-byte": edit("$ Sample", "$ Caf\xe9 sample").encode("latin-1"),
    "utf8-byte-order-mark": b"\xef\xbb\xbf" + SAMPLE.encode(),
    "crlf-line-ends": SAMPLE.replace("\n", "\r\n").encode(),
    "identical-duplicate-grid": add("GRID    3               0.0     1.144   0.0\n").encode(),
    "tabs-for-spaces": SAMPLE.replace("MAT1    1       ", "MAT1\t1\t").encode(),
}  # fmt: skip


@pytest.fixture(scope="module")
def sample_wing(tmp_path_factory) -> str:
    folder = tmp_path_factory.mktemp("sample")
    (folder / "d.bdf").write_text(SAMPLE)
    code, _, err = _run(["import", "nastran", str(folder / "d.bdf"), "--out", str(folder / "w.toml"), "--units", "in-lbf-s"])  # fmt: skip
    assert code == 0, err
    return (folder / "w.toml").read_text()


@pytest.mark.parametrize("case", list(ACCEPTED), ids=list(ACCEPTED))
def test_accepted(case, tmp_path, monkeypatch, sample_wing):
    """Decks that are odd but sound import to the sample's wing file, and write only it and
    its flutter scenario."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "d.bdf").write_bytes(ACCEPTED[case])
    code, out, err = _run(["import", "nastran", "d.bdf", *IN])
    assert code == 0 and err == "", err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["d.bdf", "w.toml", "w_flutter.toml"]
    assert (tmp_path / "w.toml").read_text() == sample_wing
    assert (tmp_path / "d.bdf").read_bytes() == ACCEPTED[case]


def test_stick_in_its_own_units(tmp_path, monkeypatch):
    """The stick of the unit cases imports in the units it is written in, to the same wing."""
    monkeypatch.chdir(tmp_path)
    (tmp_path / "c.toml").write_text(INERTIA)
    texts = []
    for scale, mass, units in ((1.0, 1.0, "si"), (1e-3, 1e3, "mm-t-s")):
        (tmp_path / "d.bdf").write_text(stick(scale, mass))
        code, out, err = _run(["import", "nastran", "d.bdf", *STICK, "--units", units])
        assert code == 0 and err == "", err
        assert "over 8 m" in out
        text = (tmp_path / "w.toml").read_text()
        texts.append(re.sub(r"(?m)^#.*\n", "", text))  # the header says the units
    for a, b in zip(texts[0].splitlines(), texts[1].splitlines(), strict=True):
        numbers = [re.findall(r"[-+]?\d[\d.]*(?:e[-+]?\d+)?", x.split("#")[0]) for x in (a, b)]
        for x, y in zip(*numbers, strict=True):
            assert float(x) == pytest.approx(float(y), rel=1e-9), (a, b)
