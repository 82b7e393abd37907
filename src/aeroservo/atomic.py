"""Atomic output files: written to temporary files in the same folder, then renamed.

An interrupted or failed run never leaves a half-written result behind, and the files of one
run are renamed into place only once every one of them has been written
(:func:`atomic_write_set`).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Callable, Sequence
from pathlib import Path

__all__ = [
    "atomic_write",
    "atomic_write_text",
    "atomic_write_set",
    "save_figure",
    "check_output_path",
]

Writer = Callable[[Path], None]


_TEMP_EXTRA = 10
"""Characters a temporary name adds to the destination's: a dot, another and 8 random."""


def check_output_path(path: str | Path, option: str = "output") -> Path:
    """Refuse an output path that cannot be written, before anything is computed.

    Parameters
    ----------
    path : str or Path
        Destination file.
    option : str
        The option or key that named it, for the message.

    Raises
    ------
    InputError
        The folder does not exist, the path is a folder, or the name (with the temporary name
        the atomic writer uses) is longer than the file system allows.
    """
    from .errors import InputError

    path = Path(path)
    folder = path.parent if str(path.parent) else Path(".")
    if not path.name or path.name in (".", ".."):
        raise InputError(f"{option} = {str(path)!r}: expected a file name")
    if not folder.is_dir():
        raise InputError(f"{option} = {str(path)!r}: folder {str(folder)!r} does not exist")
    try:
        name_max = os.pathconf(folder, "PC_NAME_MAX")
    except (OSError, ValueError, AttributeError):
        name_max = 255
    longest = name_max - _TEMP_EXTRA - len(path.suffix.encode())
    if len(path.name.encode()) > longest:
        raise InputError(
            f"{option} = {str(path)[:60]!r}...: file name of {len(path.name.encode())} bytes; "
            f"this file system allows {longest} for an output"
        )
    if path.is_dir():
        raise InputError(f"{option} = {str(path)!r}: is a folder, expected a file name")
    return path


def _temporary(path: Path) -> Path:
    check_output_path(path)
    folder = path.parent if str(path.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=folder)
    os.close(fd)
    return Path(tmp)


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def atomic_write_set(items: Sequence[tuple[str | Path, Writer]]) -> list[Path]:
    """Write several files as a set: all of them, or none.

    Parameters
    ----------
    items : sequence of (path, write)
        ``write(tmp_path)`` writes the complete file to the temporary path it is given; the
        folders must exist.

    Returns
    -------
    list of Path
        The destinations, in the order given.

    Notes
    -----
    Every file is written to a temporary name next to its destination first; only when all
    writes succeeded are they renamed into place. If a write fails (or the run is interrupted)
    the temporary files are removed and no destination is touched.
    """
    done: list[tuple[Path, Path]] = []
    try:
        for path, write in items:
            path = Path(path)
            tmp = _temporary(path)
            done.append((tmp, path))
            try:
                write(tmp)
            except OSError as exc:  # e.g. a full disk: name the file being written
                if exc.filename is not None and str(exc.filename) == str(path):
                    raise
                raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from None
        mode = 0o666 & ~_umask()
        for tmp, path in done:
            os.chmod(tmp, mode)  # mkstemp creates 0600; results follow the umask
            os.replace(tmp, path)
    except BaseException:
        for tmp, _path in done:
            tmp.unlink(missing_ok=True)
        raise
    return [path for _tmp, path in done]


def atomic_write(path: str | Path, write: Writer) -> Path:
    """Call ``write(tmp_path)`` and move the result to ``path`` only if it succeeded.

    Parameters
    ----------
    path : str or Path
        Destination; its folder must exist.
    write : callable
        Writes the complete file to the temporary path it is given.
    """
    return atomic_write_set([(path, write)])[0]


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write text atomically (UTF-8)."""
    return atomic_write(path, lambda p: p.write_text(text, encoding="utf-8"))


def figure_writer(fig, path: str | Path, **kw) -> Writer:
    """A writer of a matplotlib figure for :func:`atomic_write_set` (format from the suffix)."""
    fmt = Path(path).suffix.lstrip(".") or "png"
    return lambda p: fig.savefig(p, format=fmt, **kw)


def save_figure(fig, path: str | Path, **kw) -> Path:
    """Save a matplotlib figure atomically; the format follows the file suffix."""
    return atomic_write(path, figure_writer(fig, path, **kw))
