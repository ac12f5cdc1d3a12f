"""`horde bench`: the throughput benchmarks, whose code lives in the repository's benchmarks/ folder.

The benchmarks are not part of the installed package (they need the scenarios and are run from a
checkout, as `make` installs it: editable). This module finds the folder next to the package's source
tree, puts the checkout on `sys.path` and hands the arguments to `benchmarks.run`.
"""

from __future__ import annotations

import argparse
import importlib
import sys
from pathlib import Path
from types import ModuleType
from typing import get_args

from horde.spec import MAX_DEMONS
from horde.spec.demons import Dtype

DTYPES: tuple[str, ...] = get_args(Dtype)

CHECKOUT = Path(__file__).resolve().parents[2]  # backend/horde/bench.py -> the repository


def _benchmarks() -> ModuleType:
    if (CHECKOUT / "benchmarks" / "__init__.py").is_file() and str(CHECKOUT) not in sys.path:
        sys.path.insert(0, str(CHECKOUT))
    try:
        return importlib.import_module("benchmarks.run")
    except ImportError as exc:
        raise SystemExit(f"error: horde bench needs the repository's benchmarks/ folder ({exc})") from None


def cmd_bench(args: argparse.Namespace) -> int:
    return int(_benchmarks().bench(args))


MAX_THREADS = 64  # `--threads`: more than any machine this runs on has cores


def _demons(text: str) -> int:
    """`--demons`: a run's number of demons, 1 to MAX_DEMONS."""
    count = int(text) if text.strip().isdigit() else 0
    if not 1 <= count <= MAX_DEMONS:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number of demons from 1 to {MAX_DEMONS} (a run's limit)")
    return count


def _threads(text: str) -> list[int]:
    """`--threads`: thread counts, comma-separated, each 1 to MAX_THREADS."""
    parts = [p.strip() for p in text.split(",")]
    if not all(p.isdigit() and 1 <= int(p) <= MAX_THREADS for p in parts):
        raise argparse.ArgumentTypeError(
            f"{text!r} is not a list of thread counts (1 to {MAX_THREADS}, comma-separated)"
        )
    return [int(p) for p in parts]


def _dtypes(text: str) -> list[str]:
    """`--dtype`: weight dtypes, comma-separated: float64, float32."""
    parts = [p.strip() for p in text.split(",")]
    if not all(p in DTYPES for p in parts):
        raise argparse.ArgumentTypeError(f"{text!r} is not a list of dtypes ({', '.join(DTYPES)}, comma-separated)")
    return parts


def add_bench_parser(sub: argparse._SubParsersAction) -> None:
    bench = sub.add_parser(
        "bench", help="throughput: demon-updates per second at thesis, nexting, off-policy and control scale"
    )
    bench.add_argument("--quick", action="store_true", help="a tiny run (a few seconds), for smoke tests")
    bench.add_argument("--json", metavar="PATH", help="also write the figures as JSON")
    bench.add_argument(
        "--only",
        action="append",
        choices=("thesis", "nexting", "off_policy", "control"),
        help="run only this workload (repeatable)",
    )
    bench.add_argument(
        "--workload",
        metavar="NAME-LEARNER",
        help="instead of the table: one workload (nexting-td, nexting-gtd, ...) against the memory bound, bytes "
        "read plus written on both sides, per thread count and dtype, rounds alternated",
    )
    bench.add_argument("--demons", type=_demons, default=8000, help="with --workload: its demons (default 8000)")
    bench.add_argument(
        "--threads", type=_threads, default="1,2", help="with --workload: thread counts, comma-separated"
    )
    bench.add_argument(
        "--dtype", type=_dtypes, default="float64,float32", help="with --workload: dtypes, comma-separated"
    )
    bench.set_defaults(func=cmd_bench)
