"""Silencing what C libraries write to the process's stdout (solver banners and notes), so that
machine-readable output on stdout (``--json``) is not corrupted."""

from __future__ import annotations

import contextlib
import io
import os
import sys

__all__ = ["c_stdout_silenced", "flush_c_stdio"]


@contextlib.contextmanager
def c_stdout_silenced():
    """Send what C code writes to the process's stdout to /dev/null for a moment, so that
    machine-readable output on stdout (``--json``) is not corrupted."""
    sys.stdout.flush()
    fd = 1  # C code writes to file descriptor 1 whatever sys.stdout is
    try:
        saved = os.dup(fd)
    except OSError:  # no stdout at all
        with contextlib.redirect_stdout(io.StringIO()):
            yield
        return
    try:
        with open(os.devnull, "wb") as null, contextlib.redirect_stdout(io.StringIO()):
            os.dup2(null.fileno(), fd)  # casadi prints through Python's sys.stdout, plugins
            yield  # may print through C stdio: silence both
            flush_c_stdio()  # C stdio buffers output to a pipe: flush it into /dev/null
    finally:
        os.dup2(saved, fd)
        os.close(saved)


def flush_c_stdio() -> None:
    """Flush the C library's stdio buffers (``fflush(NULL)``)."""
    import ctypes

    try:
        ctypes.CDLL(None).fflush(None)
    except (OSError, AttributeError):  # no C library to flush (not on this platform)
        pass
