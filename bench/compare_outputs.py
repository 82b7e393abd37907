"""Run every shipped scenario and compare its outputs with another checkout's (issue 39).

A refactor must change no public result. This script runs each ``scenarios/*.toml`` (the
optimisation files with ``aeroservo optimize``, the others with ``aeroservo run``) with the
checkout's package, and writes a digest of every output: each JSON and CSV file parsed and
each NPZ array, with the fields that measure time (elapsed, cases per second, dates, folders)
left out. Two digests are compared key by key, bit for bit.

Usage::

    python bench/compare_outputs.py digest OUT.json [--src SRC] [--full]
    python bench/compare_outputs.py compare BEFORE.json AFTER.json

``--src`` is the ``src`` folder of the checkout to run (default: this one's); ``--full`` runs
the scenarios as shipped (the default runs them with ``--quick``, a few minutes in all).
"""

from __future__ import annotations

import argparse
import csv
import hashlib
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
TIMING = ("elapsed", "cases_per_second", "seconds", "wall", "date", "runtime", "solve_time")
PATHS = ("files", "folder", "source", "out", "path", "wing_source", "csv", "netcdf")


def _timing(key: str) -> bool:
    k = key.lower()
    return any(t in k for t in TIMING) or k in PATHS


def _clean(obj):
    if isinstance(obj, dict):
        return {k: _clean(v) for k, v in obj.items() if not _timing(str(k))}
    if isinstance(obj, list):
        return [_clean(v) for v in obj]
    if isinstance(obj, str) and ("/tmp" in obj or "/out" in obj or os.sep + "work" in obj):
        return Path(obj).name
    return obj


def _digest_file(path: Path):
    if path.suffix == ".json":
        return _clean(json.loads(path.read_text(encoding="utf-8")))
    if path.suffix in (".csv", ".txt"):
        rows = list(csv.reader(path.open(encoding="utf-8")))
        if rows and path.suffix == ".csv":
            keep = [i for i, h in enumerate(rows[0]) if not _timing(h)]
            rows = [[r[i] for i in keep if i < len(r)] for r in rows]
        return hashlib.sha256(json.dumps(rows).encode()).hexdigest()
    if path.suffix == ".npz":
        import numpy as np

        with np.load(path, allow_pickle=False) as z:
            out = {
                k: hashlib.sha256(np.ascontiguousarray(z[k]).tobytes()).hexdigest()
                + str(z[k].shape)
                for k in sorted(z.files)
                if not _timing(k) and k != "meta"
            }
            if "meta" in z.files:  # a JSON record with the run's summary (timing left out)
                out["meta"] = _clean(json.loads(str(z["meta"])))
            return out
    return None  # figures and NetCDF stores: not compared


def _run(src: Path, scenario: Path, out: Path, quick: bool) -> dict:
    env = dict(os.environ, PYTHONPATH=str(src), OMP_NUM_THREADS="1", OPENBLAS_NUM_THREADS="1")
    import tomllib

    tables = set(tomllib.loads(scenario.read_text(encoding="utf-8")))
    if tables & {"optimize", "codesign"}:
        cmd = ["optimize", str(scenario), "--json"]
    elif "scenario" not in tables:  # a wing file: its flutter boundary with p-k
        cmd = ["flutter", str(scenario), "--json", "--pk", "--save", str(out / "sweep.npz")]
    else:
        cmd = ["run", str(scenario), "--out", str(out), "--json", "--no-progress"]
        cmd += ["--quick"] if quick else []
    p = subprocess.run(
        [sys.executable, "-m", "aeroservo", *cmd],
        capture_output=True,
        text=True,
        env=env,
        cwd=ROOT,
    )
    record: dict = {"exit": p.returncode}
    try:
        record["stdout"] = _clean(json.loads(p.stdout))
    except json.JSONDecodeError:
        record["stdout"] = p.stdout
    record["stderr"] = [ln for ln in p.stderr.splitlines() if "elapsed" not in ln]
    for f in sorted(out.rglob("*")):
        if f.is_file():
            record[str(f.relative_to(out))] = _digest_file(f)
    return record


def digest(dest: Path, src: Path, full: bool) -> None:
    """Run every shipped scenario with the package in ``src`` and write the digest."""
    result = {}
    for sc in sorted((ROOT / "scenarios").glob("*.toml")):
        with tempfile.TemporaryDirectory() as tmp:
            print(f"{sc.name} ...", file=sys.stderr, flush=True)
            result[sc.name] = _run(src, sc, Path(tmp), not full)
    dest.write_text(json.dumps(result, indent=1, sort_keys=True), encoding="utf-8")


def _diff(a, b, where: str, out: list) -> None:
    if isinstance(a, dict) and isinstance(b, dict):
        for k in sorted(set(a) | set(b)):
            if k not in a or k not in b:
                out.append(f"{where}/{k}: only in {'after' if k in b else 'before'}")
            else:
                _diff(a[k], b[k], f"{where}/{k}", out)
    elif isinstance(a, list) and isinstance(b, list) and len(a) == len(b):
        for i, (x, y) in enumerate(zip(a, b, strict=True)):
            _diff(x, y, f"{where}[{i}]", out)
    elif a != b and not (a != a and b != b):  # NaN equals NaN here
        out.append(f"{where}: {str(a)[:80]} -> {str(b)[:80]}")


def compare(before: Path, after: Path) -> int:
    """Print every difference between two digests; 0 when there is none."""
    out: list = []
    _diff(json.loads(before.read_text()), json.loads(after.read_text()), "", out)
    print("\n".join(out) if out else "the outputs of every shipped scenario are identical")
    return 1 if out else 0


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    sub = p.add_subparsers(dest="command", required=True)
    d = sub.add_parser("digest")
    d.add_argument("dest", type=Path)
    d.add_argument("--src", type=Path, default=ROOT / "src")
    d.add_argument("--full", action="store_true")
    c = sub.add_parser("compare")
    c.add_argument("before", type=Path)
    c.add_argument("after", type=Path)
    a = p.parse_args()
    if a.command == "digest":
        digest(a.dest, a.src.resolve(), a.full)
        return 0
    return compare(a.before, a.after)


if __name__ == "__main__":
    sys.exit(main())
