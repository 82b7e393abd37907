"""The one reader of user files: wing, scenario and controller files, gust series, results.

Every file a user names goes through :func:`read_bytes` (regular files only, size capped,
so a named pipe, a device or a huge file is refused before anything is read) and text files
through :func:`read_text` (UTF-8, with or without a byte-order mark; UTF-16 and UTF-32 with a
byte-order mark, as Windows Notepad writes them, are decoded too). Every failure is one
:class:`~aeroservo.errors.InputError` line naming the file and what was expected.
"""

from __future__ import annotations

import codecs
import os
import stat
from pathlib import Path

from ..errors import InputError

__all__ = [
    "MAX_TEXT_BYTES",
    "MAX_RESULT_BYTES",
    "user_path",
    "check_readable",
    "read_bytes",
    "read_text",
]

MAX_TEXT_BYTES = 16 * 2**20
"""Largest text file read (TOML, CSV, JSON) [bytes]."""

MAX_RESULT_BYTES = 2 * 2**30
"""Largest result archive read (.npz) [bytes]."""

_BOMS = (  # longest first: the UTF-32 LE mark starts with the UTF-16 LE one
    (codecs.BOM_UTF32_LE, "utf-32"),
    (codecs.BOM_UTF32_BE, "utf-32"),
    (codecs.BOM_UTF8, "utf-8-sig"),
    (codecs.BOM_UTF16_LE, "utf-16"),
    (codecs.BOM_UTF16_BE, "utf-16"),
)
_MAGIC = {
    b"\x89PNG": "a PNG image",
    b"%PDF": "a PDF document",
    b"PK\x03\x04": "a zip archive (an .npz result?)",
    b"\x7fELF": "a program",
    b"GIF8": "a GIF image",
    b"\x93NUMPY": "a NumPy array file",
}


def user_path(value: object, what: str = "file") -> Path:
    """A path given by the user as ``str`` or ``os.PathLike`` (anything else is refused)."""
    if isinstance(value, bool) or not isinstance(value, (str, os.PathLike)):
        raise InputError(f"path = {value!r}: expected the path of a {what} (str or Path)")
    path = Path(value)
    if "\x00" in str(path):
        raise InputError(f"path = {str(path)!r}: a file name cannot contain a NUL character")
    return path


def check_readable(path: str | Path, what: str = "file") -> int:
    """The size of a regular file [bytes]; an :class:`InputError` for anything else."""
    return _size(user_path(path, what), what)


def _size(path: Path, what: str) -> int:
    try:
        st = path.stat()
    except FileNotFoundError:
        raise InputError(f"{path}: no such file") from None
    except (OSError, ValueError) as exc:  # name too long, permission, loop of links, ...
        why = getattr(exc, "strerror", None) or str(exc)
        raise InputError(f"{path}: cannot read the file ({why})") from None
    if stat.S_ISDIR(st.st_mode):
        raise InputError(f"{path}: is a folder, expected a {what}")
    if not stat.S_ISREG(st.st_mode):
        raise InputError(
            f"{path}: not a regular file (a pipe, device or socket); expected a {what}"
        )
    return st.st_size


def read_bytes(path: str | Path, *, what: str = "file", limit: int = MAX_TEXT_BYTES) -> bytes:
    """The content of a regular file of at most ``limit`` bytes.

    Parameters
    ----------
    path : str or Path
        The file.
    what : str
        What the file should be, for messages (e.g. ``"wing file (TOML)"``).
    limit : int
        Largest size accepted [bytes].

    Raises
    ------
    InputError
        Missing, a folder, not a regular file, larger than ``limit``, or unreadable.
    """
    path = user_path(path, what)
    if _size(path, what) > limit:
        raise InputError(
            f"{path}: larger than {limit / 2**20:g} MiB, the limit for a {what}; is it the "
            "right file?"
        )
    try:
        with path.open("rb") as fh:
            raw = fh.read(limit + 1)
    except OSError as exc:
        raise InputError(f"{path}: cannot read the file ({exc.strerror or exc})") from None
    if len(raw) > limit:  # grew while being read
        raise InputError(f"{path}: larger than {limit / 2**20:g} MiB, the limit for a {what}")
    return raw


def decode_text(raw: bytes, path: str | Path, what: str = "text file") -> str:
    """Text of a file's bytes: UTF-8 (a byte-order mark is dropped) or UTF-16/32 with one."""
    codec = next((c for bom, c in _BOMS if raw.startswith(bom)), None)
    if codec is None:
        codec = "utf-8"
        for magic, kind in _MAGIC.items():
            if raw.startswith(magic):
                raise InputError(f"{path}: {kind}, not a {what}")
    try:
        text = raw.decode(codec)
    except UnicodeDecodeError as exc:
        raise InputError(
            f"{path}: not a UTF-8 text file (byte {raw[exc.start]:#04x} at offset {exc.start}); "
            f"expected a {what} saved as UTF-8"
        ) from None
    if "\x00" in text:
        raise InputError(f"{path}: contains NUL characters (binary data); expected a {what}")
    return text


def read_text(path: str | Path, *, what: str = "text file", limit: int = MAX_TEXT_BYTES) -> str:
    """The text of a user file (see :func:`read_bytes` and :func:`decode_text`)."""
    return decode_text(read_bytes(path, what=what, limit=limit), path, what)


def json_output(value: object, what: str) -> Path:
    """The path of a result to write as JSON: a ``.json`` file name, or an InputError."""
    path = user_path(value, what)
    if path.suffix.lower() != ".json":
        raise InputError(f"path = {str(path)!r}: expected a .json file name")
    return path


def json_of_format(path: str | Path, fmt: str) -> bool:
    """Whether ``path`` is a ``.json`` file whose first kilobytes name the format ``fmt``."""
    path = Path(path)
    if path.suffix.lower() != ".json":
        return False
    try:
        with open(path, "rb") as fh:
            head = fh.read(4096)
    except (OSError, ValueError):
        return False
    return f'"format": "{fmt}"'.encode() in head


def write_result_items(items: dict) -> dict[str, str]:
    """Write the files of a result (``{kind: (path, writer)}``) as one set, all or none;
    returns ``{kind: path}``."""
    from ..atomic import atomic_write_set

    atomic_write_set(list(items.values()))
    return {k: str(p) for k, (p, _w) in items.items()}


def read_result_json(path: str | Path, what: str, fmt: str, older: tuple = ()) -> tuple:
    """``(path, document)`` of a result written as JSON in the format ``fmt``: an InputError
    naming the file and ``what`` it should be when it is missing, too large, not JSON, not a
    table or of another format (``older``: formats of earlier versions, named as such)."""
    import json

    path = user_path(path, f"{what} (.json)")
    raw = read_bytes(path, what=f"{what} (.json)", limit=MAX_RESULT_BYTES)

    def fail(why: str):
        raise InputError(f"{path}: not a valid aeroservo {what} ({why})")

    try:
        doc = json.loads(raw.decode("utf-8-sig"))
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        fail(f"not JSON: {' '.join(str(exc).split())}")
    if not isinstance(doc, dict) or doc.get("format") != fmt:
        found = doc.get("format") if isinstance(doc, dict) else None
        again = " (written by an older aeroservo: run the study again)" if found in older else ""
        fail(f"format {found!r}, expected {fmt!r}{again}")
    return path, doc
