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

__all__ = ["atomic_write", "atomic_write_text", "atomic_write_set", "save_figure"]

Writer = Callable[[Path], None]


def _temporary(path: Path) -> Path:
    folder = path.parent if str(path.parent) else Path(".")
    if not folder.is_dir():
        from .errors import InputError

        raise InputError(f"output = {str(path)!r}: folder {str(folder)!r} does not exist")
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
            write(tmp)
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
