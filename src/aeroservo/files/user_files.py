"""The one reader of user files: wing, scenario and controller files, gust series, results.

Every file a user names goes through :func:`read_bytes` (regular files only, size capped,
so a named pipe, a device or a huge file is refused before anything is read) and text files
through :func:`read_text` (UTF-8, with or without a byte-order mark; UTF-16 and UTF-32 with a
byte-order mark, as Windows Notepad writes them, are decoded too). Archives of arrays
(``.npz``) go through :func:`read_npz` and results written as JSON through
:func:`read_result_json`, both in bounded memory: the sizes an archive's directory and its
arrays' headers declare, and the objects a JSON text would make, are checked before anything
is inflated or parsed. Every failure is one :class:`~aeroservo.errors.InputError` line naming
the file and what was expected.
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
    "read_npz",
    "read_result_json",
]

MAX_TEXT_BYTES = 16 * 2**20
"""Largest text file read (TOML, CSV, JSON) [bytes]."""

MAX_RESULT_BYTES = 2 * 2**30
"""Largest result archive read (.npz, compressed) [bytes]."""

MAX_ARRAY_BYTES = 2**30
"""Largest total of the arrays of an archive read (.npz, inflated) [bytes]."""

MAX_DIRECTORY_BYTES = 16 * 2**20
"""Largest zip directory of an archive read (.npz: some 100 000 arrays) [bytes]."""

MAX_RESULT_JSON_BYTES = 128 * 2**20
"""Largest result written as JSON read (gust loads, limit cycles) [bytes]."""

MAX_JSON_MEMORY = 2**30
"""Largest memory the objects of a JSON text may take, as :func:`json_memory` estimates it
[bytes] (a text of many small lists or tables takes up to some 40 times its size)."""

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
    size = _size(path, what)
    if size > limit:
        raise InputError(
            f"{path}: larger than {limit / 2**20:g} MiB, the limit for a {what}; is it the "
            "right file?"
        )
    try:
        with path.open("rb") as fh:
            raw = fh.read(size + 1)  # not limit + 1: a buffer of the limit would be made
            if len(raw) > size:  # it grows while it is read
                raw += fh.read(limit + 1 - len(raw))
    except OSError as exc:
        raise InputError(f"{path}: cannot read the file ({exc.strerror or exc})") from None
    if len(raw) > limit:  # grew while being read
        raise InputError(f"{path}: larger than {limit / 2**20:g} MiB, the limit for a {what}")
    return raw


def file_head(path: str | Path, n: int, what: str = "file") -> bytes:
    """The first ``n`` bytes of a regular file (an InputError naming it otherwise)."""
    path = user_path(path, what)
    _size(path, what)
    try:
        with path.open("rb") as fh:
            return fh.read(n)
    except OSError as exc:
        raise InputError(f"{path}: cannot read the file ({exc.strerror or exc})") from None


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


def json_memory(text: str) -> int:
    """An upper estimate of the memory the objects of the JSON ``text`` take [bytes]: its
    strings (at most the text again), 200 bytes a table, 100 a list and 64 an item (a number or
    string and its place in a list or table), counted from ``{``, ``[``, ``,`` and ``:``
    (those inside strings too, so the estimate only errs high). Measured with
    :mod:`tracemalloc` against ``json.loads`` on texts of empty lists, nested lists, small
    tables, numbers and strings, and on gust-loads and limit-cycle results (3 to 7 times their
    size): never below."""
    import sys

    items = text.count(",") + text.count(":")
    return sys.getsizeof(text) + 200 * text.count("{") + 100 * text.count("[") + 64 * items


def read_result_json(path: str | Path, what: str, fmt: str, older: tuple = ()) -> tuple:
    """``(path, document)`` of a result written as JSON in the format ``fmt``: an InputError
    naming the file and ``what`` it should be when it is missing, too large (more than
    :data:`MAX_RESULT_JSON_BYTES`, or objects of more than :data:`MAX_JSON_MEMORY` by
    :func:`json_memory`), not JSON, not a table or of another format (``older``: formats of
    earlier versions, named as such)."""
    import json

    path = user_path(path, f"{what} (.json)")
    raw = read_bytes(path, what=f"{what} (.json)", limit=MAX_RESULT_JSON_BYTES)

    def fail(why: str):
        raise InputError(f"{path}: not a valid aeroservo {what} ({why})")

    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        fail(f"not UTF-8 text: byte {raw[exc.start]:#04x} at offset {exc.start}")
    del raw
    need = json_memory(text)
    if need > MAX_JSON_MEMORY:
        fail(
            f"its {len(text)} characters would take some {need / 2**20:.0f} MiB of memory as "
            f"objects, more than the {MAX_JSON_MEMORY / 2**20:g} MiB allowed"
        )
    try:
        doc = json.loads(text)
    except (json.JSONDecodeError, RecursionError) as exc:
        fail(f"not JSON: {' '.join(str(exc).split())}")
    if not isinstance(doc, dict) or doc.get("format") != fmt:
        found = doc.get("format") if isinstance(doc, dict) else None
        again = " (written by an older aeroservo: run the study again)" if found in older else ""
        fail(f"format {found!r}, expected {fmt!r}{again}")
    return path, doc


def _directory_size(fh, size: int) -> int | None:
    """The size of the central directory of the zip archive open in ``fh`` (``size`` bytes
    long) from its end record, found as :mod:`zipfile` finds it; None without one."""
    import struct

    tail_len = min(size, 22 + 65535)  # the end record and the longest comment
    fh.seek(size - tail_len)
    tail = fh.read(tail_len)
    at = len(tail) - 22
    if at < 0 or tail[at : at + 4] != b"PK\x05\x06" or tail[-2:] != b"\x00\x00":
        at = tail.rfind(b"PK\x05\x06")
    if at < 0 or len(tail) - at < 22:
        return None
    return struct.unpack("<I", tail[at + 12 : at + 16])[0]


def _member_header(zf, info) -> tuple:
    """``(shape, dtype)`` an archive member's ``.npy`` header declares (its data unread)."""
    import numpy.lib.format as npy

    with zf.open(info) as fp:
        version = npy.read_magic(fp)
        if version == (1, 0):
            shape, _fortran, dtype = npy.read_array_header_1_0(fp)
        elif version == (2, 0):
            shape, _fortran, dtype = npy.read_array_header_2_0(fp)
        else:
            raise ValueError(f"array {info.filename!r}: .npy format {version}")
    return shape, dtype


def read_npz(
    path: str | Path,
    *,
    what: str = "archive of arrays (.npz)",
    names: tuple | None = None,
    limit: int = MAX_RESULT_BYTES,
    budget: int | None = None,
) -> dict:
    """The arrays of a NumPy ``.npz`` archive, read in bounded memory: a file of at most
    ``limit`` bytes, a zip directory of at most :data:`MAX_DIRECTORY_BYTES`, and arrays of
    at most ``budget`` bytes in all as the directory and each array's header declare
    them, all checked before anything is inflated (and :mod:`zipfile` inflates no member
    beyond the size its directory entry gives). No pickled objects.

    Parameters
    ----------
    path : str or Path
        The archive.
    what : str
        What it should be, for messages.
    names : tuple of str, optional
        Read only these arrays (those present); the others are neither inflated nor counted.
    limit : int
        Largest file accepted [bytes].
    budget : int, optional
        Largest total of the arrays read [bytes] (default :data:`MAX_ARRAY_BYTES`).

    Returns
    -------
    dict
        ``{name: array}`` (names without the ``.npy`` of the members).

    Raises
    ------
    InputError
        Naming the file: missing, too large, not a zip archive, damaged, an array too large
        or not an ``.npy`` array of plain data.
    """
    import math
    import zipfile
    import zlib

    import numpy.lib.format as npy

    path = user_path(path, what)
    size = _size(path, what)
    if size > limit:
        raise InputError(f"{path}: larger than {limit / 2**20:g} MiB, the limit for a {what}")
    budget = MAX_ARRAY_BYTES if budget is None else budget
    out: dict = {}
    try:
        with path.open("rb") as fh:
            cd = _directory_size(fh, size)
            if cd is None:
                raise InputError(
                    f"{path}: not a .npz archive (no zip directory); expected the {what}"
                )
            if cd > MAX_DIRECTORY_BYTES:
                raise InputError(
                    f"{path}: a zip directory of {cd / 2**20:.0f} MiB, more than the "
                    f"{MAX_DIRECTORY_BYTES / 2**20:g} MiB allowed for the {what}"
                )
            fh.seek(0)
            with zipfile.ZipFile(fh) as zf:
                members = [
                    i for i in zf.infolist()
                    if names is None or i.filename.removesuffix(".npy") in names
                ]  # fmt: skip
                total = sum(i.file_size for i in members)
                if total > budget:
                    big = max(members, key=lambda i: i.file_size)
                    raise InputError(
                        f"{path}: its arrays inflate to {total / 2**20:.0f} MiB (array "
                        f"{big.filename.removesuffix('.npy')!r}: {big.file_size / 2**20:.0f} "
                        f"MiB), more than the {budget / 2**20:g} MiB allowed for the {what}"
                    )
                for info in members:
                    key = info.filename.removesuffix(".npy")
                    if info.compress_type not in (zipfile.ZIP_STORED, zipfile.ZIP_DEFLATED):
                        raise ValueError(f"array {key!r}: compression {info.compress_type}")
                    if not info.filename.endswith(".npy") or key in out:
                        raise ValueError(f"member {info.filename!r} is not one .npy array")
                    shape, dtype = _member_header(zf, info)
                    if dtype.hasobject:
                        raise ValueError(f"array {key!r} holds Python objects (pickled)")
                    if math.prod(shape) * max(dtype.itemsize, 1) > info.file_size:
                        raise ValueError(
                            f"array {key!r} of shape {shape} is larger than its "
                            f"{info.file_size} bytes in the archive"
                        )
                    with zf.open(info) as fp:
                        out[key] = npy.read_array(fp, allow_pickle=False)
    except InputError:
        raise
    except OSError as exc:
        raise InputError(f"{path}: cannot read the file ({exc.strerror or exc})") from None
    except (ValueError, EOFError, RuntimeError, zipfile.BadZipFile, zlib.error) as exc:
        why = " ".join(str(exc).split())[:160] or type(exc).__name__
        raise InputError(f"{path}: not a readable {what} ({why})") from None
    return out
