"""A Nastran deck file parsed by pyNastran, with its failures as one line.

The file must be a regular file of at most :data:`MAX_DECK_BYTES` (a stick model is a few
kilobytes; a FIFO or a device would never end). It is decoded as Latin-1, which accepts every
byte (comments in old decks carry accented characters), and parsed in a scratch working
folder, so that pyNastran's ``pyNastran_crash.bdf`` of a failed read is not left behind.
pyNastran is an optional dependency (``pip install 'aeroservo[nastran]'``), imported only here.
"""

from __future__ import annotations

import contextlib
import io
import re
import stat
import tempfile
from pathlib import Path

from ...errors import InputError

__all__ = ["pynastran_bdf", "parse_deck", "first_line", "MAX_DECK_BYTES"]

MAX_DECK_BYTES = 64 * 1024**2
"""Largest deck read [bytes] (64 MiB: a stick model with its aero cards is far smaller)."""


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


def parse_deck(path: Path):
    """The pyNastran model of a deck file, not cross-referenced.

    Raises
    ------
    InputError
        One line: not a regular file, too large, unreadable, or what pyNastran reports.
    """
    try:
        info = path.stat()
    except OSError as exc:
        raise InputError(f"{path}: cannot read the deck: {exc.strerror or exc}") from None
    if not stat.S_ISREG(info.st_mode):
        raise InputError(f"{path}: not a regular file (a Nastran deck is a text file)")
    if info.st_size > MAX_DECK_BYTES:
        raise InputError(
            f"{path}: {info.st_size / 1024**2:.0f} MiB: larger than the "
            f"{MAX_DECK_BYTES // 1024**2} MiB a stick-model deck needs"
        )
    try:
        text = path.read_text(encoding="latin-1")
    except OSError as exc:
        raise InputError(f"{path}: cannot read the deck: {exc.strerror or exc}") from None
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
            model.read_bdf(full, punch=punch, xref=False, encoding="latin-1")
    except Exception as exc:  # pyNastran raises many kinds on a malformed deck
        raise InputError(f"{path}: cannot read the deck: {first_line(exc)}") from None
    return model
