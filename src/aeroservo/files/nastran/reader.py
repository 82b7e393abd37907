"""A Nastran deck file parsed by pyNastran, with its failures as one line.

The deck and its INCLUDE files (found next to the deck, as pyNastran finds them) are read by
the one reader of user files (regular files only: a FIFO or a device is refused unopened; at
most :data:`MAX_DECK_BYTES` together) and scanned (:func:`scan_deck`) before pyNastran sees
them: a missing, repeated or binary file, a field that is not a finite number and a ``THRU``
range longer than :data:`MAX_RANGE` are refused in one line naming the deck, the card, the
field and the line. The text is UTF-8 or else Latin-1 (accented comments of old decks).
pyNastran parses it in a scratch working folder, so that its ``pyNastran_crash.bdf`` is never
left behind. pyNastran is an optional dependency (``pip install 'aeroservo[nastran]'``).
"""

from __future__ import annotations

import codecs
import contextlib
import io
import math
import os
import re
import tempfile
from pathlib import Path

from ...errors import InputError
from ..user_files import check_readable, read_bytes

__all__ = ["pynastran_bdf", "parse_deck", "scan_deck", "same_file", "first_line", "MAX_DECK_BYTES"]

MAX_DECK_BYTES = 8 * 1024**2
"""Largest deck read, its INCLUDE files with it [bytes] (8 MiB: a stick model with its aero
cards is a few kilobytes; pyNastran needs about 30 times the text's size in memory)."""

MAX_RANGE = 100_000
"""Most ids one ``THRU`` range (or values one ``FLFACT ... THRU``) may give."""

_FIELDS = {  # field names of the first line, for messages
    "GRID": {4: "X1", 5: "X2", 6: "X3"}, "MAT1": {3: "E", 4: "G", 5: "NU", 6: "RHO"},
    "CONM2": {5: "M", 6: "X1", 7: "X2", 8: "X3"}, "CMASS2": {3: "M"}, "PMASS": {3: "M"},
    "PBAR": {4: "A", 5: "I1", 6: "I2", 7: "J", 8: "NSM"}, "PARAM": {3: "V1"},
    "AERO": {3: "VELOCITY", 4: "REFC", 5: "RHOREF"},
}  # fmt: skip


def pynastran_bdf():
    """pyNastran's ``BDF`` class, or a one-line :class:`InputError` saying how to install it."""
    try:
        import numpy as np_

        old = "in1d"  # pyNastran 1.4 binds np.in1d on import; numpy 2.4 removed it
        shim = not hasattr(np_, old)
        if shim:
            setattr(np_, old, lambda a, b, **kw: np_.isin(np_.ravel(a), b, **kw))
        try:
            from pyNastran.bdf.bdf import BDF
        finally:
            if shim:
                delattr(np_, old)
    except ImportError:
        raise InputError(
            "reading a Nastran deck needs pyNastran, an optional dependency: "
            "pip install 'aeroservo[nastran]' (docs/nastran.md)"
        ) from None
    return BDF


def first_line(exc: BaseException) -> str:
    """The first line of an exception's message (with the card pyNastran names, if any)."""
    text = str(exc).strip()
    line = text.splitlines()[0].strip() if text else type(exc).__name__
    card = re.search(r"card=\[\s*'(\w+)'\s*,\s*'?(\w+)", text)
    if card:
        line += f" (card {card.group(1)} {card.group(2)})"
    return line[:300]


def _decode(raw: bytes, where: str) -> tuple[str, bool]:
    """UTF-8 text (a byte-order mark dropped), else Latin-1, and whether it was UTF-8; a
    UTF-16/32 or binary file is refused."""
    for bom in (codecs.BOM_UTF32_LE, codecs.BOM_UTF32_BE, codecs.BOM_UTF16_LE, codecs.BOM_UTF16_BE):
        if raw.startswith(bom) and not raw.startswith(codecs.BOM_UTF8):
            raise InputError(
                f"{where}: UTF-16 or UTF-32 text (byte-order mark): save the deck as ASCII, "
                "Latin-1 or UTF-8"
            )
    nul = raw.find(b"\x00")
    if nul >= 0:
        line = raw.count(b"\n", 0, nul) + 1
        raise InputError(
            f"{where}: a NUL byte on line {line} (byte {nul}): a binary file (an OP2, a "
            "compressed or a UTF-16 file?), not a text deck"
        )
    try:
        text, utf8 = raw.decode("utf-8-sig"), True
    except UnicodeDecodeError:
        text, utf8 = raw.decode("latin-1"), False
    return text.replace("\r\n", "\n").replace("\r", "\n"), utf8


def _number(token: str) -> float | None:
    """A Nastran real (``1.5``, ``1.5+3``, ``1.5D3``, ``nan``) as a float, or None."""
    t = token.strip().lower().replace("d", "e")
    t = re.sub(r"^([+-]?(?:\d+\.?\d*|\.\d+))([+-]\d+)$", r"\1e\2", t)
    try:
        return float(t)
    except ValueError:
        return None


_SUSPECT = re.compile(r"thru|nan|inf|[ed+-]0*\d{3}|\d{300}", re.I)
"""What a line needs for a field that is not finite or a THRU range (its fields are read)."""


def _line_fields(body: str) -> tuple[str, list[str]]:
    """The first field and the data fields (free, small or large field; no continuation)."""
    if "," in body:
        parts = [p.strip() for p in body.split(",")]
        return parts[0], parts[1:9]
    name, width = body[:8].strip(), 16 if "*" in body[:8] else 8
    return name, [body[8 + width * k : 8 + width * (k + 1)].strip() for k in range(64 // width)]


class _Scan:
    """The deck and its INCLUDE files, walked in pyNastran's order (see :func:`scan_deck`)."""

    def __init__(self, deck: Path):
        self.deck = deck
        self.folder = Path(os.path.dirname(os.path.abspath(deck)))  # pyNastran's include_dir
        self.files: list[Path] = []
        self.left = MAX_DECK_BYTES
        self.card: list = []  # the lines of the card being read: [(body, number, file), ...]
        self.suspect = False  # one of them has a THRU, a nan, an inf or a 3-digit exponent
        self.end = False  # ENDDATA read
        self.utf8 = True  # every file is UTF-8 (else all are read as Latin-1)
        self.in_set = False  # a case-control SET continued on the next line

    def read(self, path: Path, where: str) -> str:
        """A file's text, checked by the reader of user files, within the deck's size."""
        size = check_readable(path, "Nastran deck")
        if size > self.left:
            raise InputError(
                f"{path}: {size / 1024**2:.3g} MiB"
                + (" with the files before it" if self.files else "")
                + f": more than the {MAX_DECK_BYTES // 1024**2} MiB a stick-model deck needs; "
                "is it the right file?"
            )
        raw = read_bytes(path, what="Nastran deck", limit=self.left)
        self.left -= len(raw)
        self.files.append(path)
        text, utf8 = _decode(raw, where)
        self.utf8 = self.utf8 and utf8
        return text

    def walk(self, path: Path, text: str, bulk: bool) -> bool:
        """Scan one file's lines; returns whether the bulk data has begun."""
        where = "" if path == self.deck else f" of {path.name}"
        lines = text.split("\n")
        i = 0
        while i < len(lines):
            line = lines[i].rstrip("\r\n\t")
            if line[:7].upper() == "INCLUDE":
                i, bulk = self.include(lines, i, f"line {i + 1}{where}", bulk)
                continue
            body = line.split("$", 1)[0]
            if not bulk:
                bulk = re.match(r"\s*BEGIN\s+BULK", body, re.I) is not None
                self.control(body, f"line {i + 1}{where}")
            elif not self.end and body.strip():
                self.bulk(body, i + 1, where)
            i += 1
        self.finish()
        return bulk

    def include(self, lines: list[str], i: int, at: str, bulk: bool) -> tuple[int, bool]:
        """The INCLUDE statement at line ``i`` (continued while its quote is open, as pyNastran
        reads it): its file checked, read and walked."""
        self.finish()
        line = lines[i].rstrip("\r\n\t")
        base = line.split("$")[0]
        card = [base.strip()]
        j = i + 1
        name = base[8:].strip()
        if "'" in base and not (name.startswith("'") and name.endswith("'")):
            while not line.split("$")[0].endswith("'") and j < len(lines):
                line = lines[j].split("$")[0].strip()
                card.append(line)
                j += 1
        head = f"{self.deck}: {' '.join(card)} ({at})"
        try:
            from pyNastran.bdf.bdf_interface.include_file import get_include_filename

            target = Path(str(get_include_filename(card, include_dir=str(self.folder))))
        except ImportError:
            target = self.folder / card[0][7:].strip().strip("'\"")
        except Exception as exc:  # pyNastran's SyntaxError, AssertionError on a bad path
            raise InputError(f"{head}: {first_line(exc)}") from None
        if not target.exists():
            raise InputError(
                f"{head}: {target} does not exist (INCLUDE files are found next to the deck)"
            )
        if any(same_file(target, f) for f in self.files):
            raise InputError(f"{head}: {target} is read already (each file is read once)")
        try:
            text = self.read(target, head)
        except InputError as exc:
            raise InputError(f"{head}: {exc}") from None
        return j, self.walk(target, text, bulk)

    def control(self, body: str, at: str) -> None:
        """Case control: a ``SET n = a THRU b`` range of at most :data:`MAX_RANGE` ids."""
        tokens = [t for t in re.split(r"[\s,=()]+", body.upper()) if t]
        if tokens[:1] == ["SET"] or self.in_set:
            self.ranges(tokens, "case control SET", [at] * len(tokens))
            self.in_set = body.rstrip().endswith(",")

    def bulk(self, body: str, number: int, where: str) -> None:
        """One line of bulk data: a new card, or a continuation of the card being read."""
        body = body.expandtabs(8) if "\t" in body else body
        first = (body.split(",", 1)[0] if "," in body else body[:8]).strip()
        if first[:1] not in ("", "+", "*"):
            self.finish()
            if re.match(r"ENDDATA", first, re.I):
                self.end = True
                return
        self.card.append((body, number, where))
        self.suspect = self.suspect or _SUSPECT.search(body) is not None

    def finish(self) -> None:
        """Check the card read: every number finite, every THRU range short."""
        card, suspect, self.card, self.suspect = self.card, self.suspect, [], False
        if not (card and suspect):
            return
        rows = [(*_line_fields(body), n, where) for body, n, where in card]
        name = rows[0][0].rstrip("*").upper()
        ident = "" if name in ("AERO", "AEROS", "MKAERO1", "MKAERO2", "GRDSET") else rows[0][1][0]
        label = f"{name} {ident}".strip()
        large = "*" in rows[0][0]
        tokens, places = [], []
        for p, (_first, data, number, where) in enumerate(rows):
            row, base = (p // 2, 2 + (p % 2) * 4) if large else (p, 2)
            for k, tok in enumerate(data):
                value = _number(tok) if tok else None
                if value is not None and not math.isfinite(value):
                    field = base + k
                    known = _FIELDS.get(name, {}).get(field) if row == 0 else None
                    what = f"{known} (field {field})" if known else f"field {field}"
                    raise InputError(
                        f"{self.deck}: {label}: {what}{f' of continuation {row}' if row else ''}"
                        f" = {tok} (line {number}{where}): not a finite number"
                    )
                if tok:
                    tokens.append(tok.upper())
                    places.append(f"line {number}{where}")
        self.ranges(tokens, label, places)

    def ranges(self, tokens: list[str], label: str, places: list[str]) -> None:
        """Refuse a ``THRU`` range of more than :data:`MAX_RANGE` values."""
        for k, tok in enumerate(tokens):
            if tok != "THRU" or k == 0 or k + 1 >= len(tokens):
                continue
            if label.startswith("FLFACT"):
                nf = tokens[k + 2] if k + 2 < len(tokens) else ""
                count, what = _int(nf), f"NF = {nf}"
            else:
                start, stop = _int(tokens[k - 1]), _int(tokens[k + 1])
                by = _int(tokens[k + 3]) if k + 3 < len(tokens) and tokens[k + 2] == "BY" else 1
                count = None if start is None or stop is None else (stop - start) // max(by or 1, 1)
                what = f"{tokens[k - 1]} THRU {tokens[k + 1]}"
            if count is not None and count > MAX_RANGE:
                raise InputError(
                    f"{self.deck}: {label}: {what} ({places[k]}): {count} values, more than the "
                    f"{MAX_RANGE} a stick model may list in one range"
                )


def _int(token: str) -> int | None:
    try:
        return int(token)
    except ValueError:
        return None


def same_file(a: Path, b: Path) -> bool:
    """Whether two paths name one file (the same resolved path, or the same inode)."""
    if Path(a).resolve() == Path(b).resolve():
        return True
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def scan_deck(path: str | Path) -> tuple[str, tuple[Path, ...]]:
    """Read and check a deck and the files it INCLUDEs (before pyNastran reads them).

    Returns
    -------
    text : str
        The deck's own text (newlines as ``\\n``).
    files : tuple of Path
        The deck, then every INCLUDE file in the order read.
    encoding : str
        ``"utf-8-sig"`` when every file is UTF-8, else ``"latin-1"``.

    Raises
    ------
    InputError
        One line naming the deck: a file that is missing, not a regular file, binary, UTF-16,
        read twice, or beyond :data:`MAX_DECK_BYTES` with the others; an INCLUDE that names
        such a file (with the INCLUDE statement and its line); a field that is not a finite
        number (with its card, field and line); a ``THRU`` range of more than
        :data:`MAX_RANGE` ids.
    """
    path = Path(path)
    scan = _Scan(path)
    text = scan.read(path, str(path))
    punch = re.search(r"^\s*BEGIN\s+BULK", text, re.I | re.M) is None
    scan.walk(path, text, punch)
    return text, tuple(scan.files), "utf-8-sig" if scan.utf8 else "latin-1"


def _card_text(text: str) -> str:
    """A card printed by pyNastran as one short line (comment lines dropped)."""
    words = [w for ln in text.splitlines() if not ln.lstrip().startswith("$") for w in ln.split()]
    return " ".join(words)[:100]


def _parse_error(model, exc: BaseException) -> str:
    """What pyNastran's failure says, in one line: a card given twice with its two versions,
    the card a field failed on, or the first line of its message."""
    for attr, store, key in (
        ("_duplicate_elements", "elements", "eid"),
        ("_duplicate_properties", "properties", "pid"),
        ("_duplicate_masses", "masses", "eid"),
        ("_duplicate_materials", "materials", "mid"),
        ("_duplicate_coords", "coords", "cid"),
    ):
        twice = getattr(model, attr, None) or []
        if twice:
            new = twice[0]
            ident = getattr(new, key, "")
            old = (getattr(model, store, None) or {}).get(ident)
            both = f" ('{_card_text(str(old))}' and '{_card_text(str(new))}')" if old else ""
            return f"{new.type} {ident} is given twice, with different fields{both}"
    text = str(exc)
    grid = re.match(r"nid=(\d+)\s*\nold_node=\s*\n(.*?)\nnew_node=\s*\n(.*)", text, re.S)
    if grid:
        old, new = _card_text(grid.group(2)), _card_text(grid.group(3))
        return f"GRID {grid.group(1)} is given twice, with different fields ('{old}' and '{new}')"
    stored = getattr(model, "_stored_parse_errors", None) or []
    if stored:
        name, error = stored[0]
        message = "".join(error) if isinstance(error, list) else str(error)
        twice = re.search(r"key=(\w+);", message)
        if twice and "old_" in message:
            return f"{name} {twice.group(1)} is given twice, with different fields"
        lines = [ln.strip() for ln in message.splitlines() if ln.strip()] or [type(exc).__name__]
        why = re.sub(r"^\w+: ", "", lines[0])  # the exception's type
        return f"cannot read the deck: {name}: {why}"[:300]
    return f"cannot read the deck: {first_line(exc)}"


def parse_deck(path: Path):
    """The pyNastran model of a deck file, not cross-referenced.

    Raises
    ------
    InputError
        One line: what :func:`scan_deck` refuses, or what pyNastran reports.
    """
    text, _files, encoding = scan_deck(path)
    BDF = pynastran_bdf()
    from cpylog import SimpleLogger

    model = BDF(log=SimpleLogger(level="critical"))
    lines = text.splitlines(True)
    # pyNastran 1.3 reads the '$ pyNastran:' header lines in the locale's encoding and fails
    # on a Latin-1 byte; read them from the text already decoded
    model._parse_primary_file_header = lambda _name: model._check_pynastran_header(lines)
    punch = re.search(r"^\s*BEGIN\s+BULK", text, re.I | re.M) is None
    sink = io.StringIO()
    full = str(path.resolve())  # before the working folder changes
    try:
        with (
            tempfile.TemporaryDirectory(prefix="aeroservo-nastran-") as scratch,
            contextlib.chdir(scratch),
            contextlib.redirect_stdout(sink),
            contextlib.redirect_stderr(sink),
        ):
            model.read_bdf(full, punch=punch, xref=False, encoding=encoding)
    except Exception as exc:  # pyNastran raises many kinds on a malformed deck
        raise InputError(f"{path}: {_parse_error(model, exc)}") from None
    return model
