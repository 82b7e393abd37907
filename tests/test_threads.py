"""BLAS pools are limited inside aeroservo's compute entry points and restored outside."""

import numpy as np
import pytest
from threadpoolctl import threadpool_info, threadpool_limits

import aeroservo as aes
from aeroservo._threads import blas_limited, blas_threads
from aeroservo.errors import InputError


def blas_pools() -> list[int]:
    return [p["num_threads"] for p in threadpool_info() if p["user_api"] == "blas"]


def test_limited_inside_restored_outside(monkeypatch):
    seen = []

    @blas_limited
    def work():
        np.ones((2, 2)) @ np.ones((2, 2))  # numpy's BLAS is loaded (run alone, nothing else has)
        seen.extend(blas_pools())

    with threadpool_limits(limits=2, user_api="blas"):
        before = blas_pools()
        work()
        assert blas_pools() == before
    assert seen and all(n == 1 for n in seen)
    monkeypatch.setenv("AEROSERVO_BLAS_THREADS", "2")
    assert blas_threads() == 2
    monkeypatch.setenv("AEROSERVO_BLAS_THREADS", "many")
    with pytest.raises(InputError, match="AEROSERVO_BLAS_THREADS = 'many'"):
        blas_threads()


def test_flutter_boundary_runs_single_threaded(goland10, monkeypatch):
    import aeroservo.stability.boundary as bd

    seen = []
    original = bd.sweep_branches

    def spy(*a, **k):
        seen.extend(blas_pools())
        return original(*a, **k)

    monkeypatch.setattr(bd, "sweep_branches", spy)
    aes.flutter_boundary(goland10, 1.225)
    assert seen and all(n == 1 for n in seen)
