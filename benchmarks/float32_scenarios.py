"""Every shipped scenario in float64 and in float32, each judged by its own criterion (issue 27, what must hold 2).

    python -m benchmarks.float32_scenarios [--only NAME ...] [--workers 2] [--json FILE]

A scenario runs twice, once with `[learning] dtype = "float64"` and once with `"float32"` (nothing else
changed), and each run is judged by the bound its float64 results are held to elsewhere:

* the thesis scenarios (`experiment1`, `experiment2-*`) and `classroom-offpolicy`: every trial of the protocol
  as `horde run` runs it (`studies.base_alpha.trial`: learning, the Monte-Carlo truth with the trial's
  generator), then each demon's mean prediction at the start within 5 % (0.05 for a probability) of its mean
  exact answer (`studies.exact_check`'s bound) and each prediction demon's (not the control demon `base`)
  within the same bound of its mean Monte-Carlo truth (`base_alpha.thesis_criterion`);
* `experiment3`: at least 98 of the 100 greedy test runs end in the positive terminal (`base_alpha.meets`);
  `experiment3-base`'s ends are chance (the README): reported, not judged;
* `mountaincar-nexting`: the questions the features represent (at least 90) within 10 % of the realised returns,
  `acrobot-offpolicy`: all 24 within 0.05 or 5 % (`tests/worlds/test_gym_scenarios.py`);
* the chains: every state's value within 0.05, or 5 % of the exact values' range, of the TD fixed point
  (`tests/worlds/test_chains.py`; with tabular features the fixed point is the exact answer);
* `baird`: TD is reported diverged, GTD, GQ and ETD are not and stay bounded (`tests/worlds/test_baird_protocol.py`);
* `mountaincar-log`: the position demons (but gamma 0.98) within 5 % of the realised returns on the shipped log
  (`tests/worlds/test_streams.py`);
* `nexting` (no protocol): 10,000 steps of the scenario's 1710 demons; float32's predictions within 1e-5 of
  float64's, relative to their largest magnitude (the issue's bound for the nexting stream).

The table gives per scenario the criterion, its bound, each dtype's result (the judged number nearest its bound)
and whether it holds, and each run's wall and CPU seconds. `--workers` runs scenarios in that many processes.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
import os
import re
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
DTYPES = ("float64", "float32")
THESIS_LATTICE = ("experiment1", "experiment2-whole", "experiment2-start", "experiment2-none", "experiment2-large",
                  "experiment2-small", "classroom-offpolicy")  # fmt: skip
COUNTS = ("experiment3", "experiment3-base")
CHAINS = ("random-walk-5", "random-walk-19", "random-walk-1000", "boyan-chain")
NEXTING_STEPS = 10_000
NEXTING_BOUND = 1e-5  # relative to the largest float64 prediction
LOG = ROOT / "examples" / "data" / "mountaincar-pump.csv"


@dataclass(frozen=True)
class Judged:
    """One run of one scenario, judged."""

    figure: str  # the result in a few words: the judged number nearest its bound
    holds: bool | None  # None: nothing to judge (a chance outcome, or the reference of a comparison)
    wall: float = 0.0
    cpu: float = 0.0


@dataclass(frozen=True)
class Row:
    scenario: str
    criterion: str
    bound: str
    results: dict[str, Judged]  # by dtype


def with_dtype(spec: Any, dtype: str) -> Any:
    """The spec with `[learning] dtype` set and nothing else changed (validated again)."""
    from horde.spec import RunSpec

    body = spec.model_dump(by_alias=True)
    body["learning"]["dtype"] = dtype
    return RunSpec.model_validate(body)


# ----------------------------------------------------------------------------------------------
# The criteria, one per kind of scenario: each judges one run (a spec in one dtype).


def _trials(name: str, spec: Any) -> list[dict[str, Any]]:
    from horde.studies.base_alpha import trial
    from horde.studies.task import has_exact_answers

    lattice = has_exact_answers(spec, [d.name for d in spec.demons])
    return [trial(spec, n, lattice) for n in range(spec.protocol.trials)]


def judge_lattice(name: str, spec: Any) -> Judged:
    """Every demon's mean prediction at the start against its mean exact answer; each prediction demon's (not
    `base`) against its mean Monte-Carlo truth; both within 5 % (0.05 for a probability)."""
    from horde.studies.base_alpha import exact_checks

    trials = _trials(name, spec)
    checks = exact_checks({"scenario": name, "trials": trials})
    gaps: list[tuple[float, str]] = []  # (fraction of the bound, what it says)
    for c in checks:
        unit = "" if c.probability else " %"
        scale = 1.0 if c.probability else 100.0
        gaps.append((c.error / c.tolerance, f"{c.demon} vs exact {scale * c.error:.3g}{unit}"))
        if c.demon == "base" or c.demon not in trials[0]["truths"]:
            continue
        prediction = float(np.mean([t["predictions"][c.demon] for t in trials]))
        truth = float(np.mean([t["truths"][c.demon] for t in trials]))
        gap = abs(prediction - truth) if c.probability else abs(prediction - truth) / abs(truth)
        gaps.append((gap / c.tolerance, f"{c.demon} {prediction:.4g} vs MC {truth:.4g}: {scale * gap:.3g}{unit}"))
    worst = max(gaps)
    thesis = [text for _, text in gaps if " vs MC " in text]
    shown = [worst[1], *[t for t in thesis if t != worst[1]][:1]]
    return Judged("; ".join(shown) + f" (worst {worst[0]:.2f} of the bound)", all(g <= 1.0 for g, _ in gaps))


def judge_counts(name: str, spec: Any) -> Judged:
    """The greedy test runs' ends summed over the trials; `experiment3` needs at least 98 positive of 100."""
    trials = _trials(name, spec)
    total = {k: sum(t["counts"][k] for t in trials) for k in ("positive", "negative", "none")}
    figure = f"{total['positive']} / {total['negative']} / {total['none']}"
    return Judged(figure, total["positive"] >= 98 if name == "experiment3" else None)


def representable(name: str) -> bool:
    """The MountainCar questions the features represent (README): the discounted position and velocity at every
    timescale and policy, and "above x" for x below 0 (the valley) up to gamma 0.95."""
    if name.startswith(("position_", "velocity_")):
        return True
    above = re.fullmatch(r"above(-?[0-9.]+)_g([0-9.]+)_\w+", name)
    return above is not None and float(above.group(1)) < 0 and float(above.group(2)) <= 0.95


def judge_mountaincar(name: str, spec: Any) -> Judged:
    from horde.worlds.protocol import run_gym_protocol

    result = run_gym_protocol(spec)
    claimed = [d for d in result.demons if representable(d.name)]
    within = [d for d in claimed if d.relative is not None and d.relative <= 0.10]
    worst = max(claimed, key=lambda d: np.inf if d.relative is None else d.relative)
    relative = "none" if worst.relative is None else f"{100 * worst.relative:.1f} %"
    figure = f"{len(within)} of {len(claimed)} within 10 %; worst {worst.name} {relative}"
    return Judged(figure, len(claimed) >= 90 and len(within) == len(claimed))


def judge_acrobot(name: str, spec: Any) -> Judged:
    from horde.worlds.protocol import run_gym_protocol

    result = run_gym_protocol(spec)

    def fraction(d: Any) -> float:
        if d.error is None or d.truth is None:
            return np.inf
        return float(abs(d.error) / max(0.05, 0.05 * abs(d.truth)))

    worst = max(result.demons, key=fraction)
    within = sum(fraction(d) <= 1.0 for d in result.demons)
    figure = f"{within} of {len(result.demons)} within; worst {worst.name} at {fraction(worst):.2f} of its bound"
    return Judged(figure, len(result.demons) == 24 and within == 24)


def judge_chain(name: str, spec: Any) -> Judged:
    from horde.worlds.protocol import run_gym_protocol

    result = run_gym_protocol(spec)
    worst_fraction, worst_name, worst_gap = 0.0, "", 0.0
    for row in result.demons:
        values = row.values or {}
        exact = np.array(values["exact"])
        tolerance = max(0.05, 0.05 * float(exact.max() - exact.min()))
        gap = float(np.abs(np.array(values["values"]) - np.array(values["fixed_point"])).max())
        if gap / tolerance >= worst_fraction:
            worst_fraction, worst_name, worst_gap = gap / tolerance, row.name, gap
    return Judged(f"worst {worst_name}: {worst_gap:.3g} from the fixed point ({worst_fraction:.2f} of the bound)",
                  worst_fraction <= 1.0)  # fmt: skip


def judge_baird(name: str, spec: Any) -> Judged:
    from horde.worlds.protocol import run_gym_protocol

    rows = {row.name: row for row in run_gym_protocol(spec).demons}
    bounded = ("gtd", "gq", "etd")
    largest = max(abs(rows[n].prediction) for n in bounded)
    holds = rows["td"].diverged and all(not rows[n].diverged and abs(rows[n].prediction) < 100 for n in bounded)
    td = "diverged" if rows["td"].diverged else f"not diverged ({rows['td'].prediction:.3g})"
    return Judged(f"td {td}; gtd, gq, etd predictions within ±{largest:.3g}", holds)


def judge_log(name: str, spec: Any) -> Judged:
    from horde.worlds.log_run import learn_log

    result = learn_log(spec, LOG)
    judged = [d for d in result.demons if d.name.startswith("position") and not d.name.endswith("0.98")]
    gaps = [(abs(d.mean_prediction - d.mean_return) / abs(d.mean_return), d.name) for d in judged]  # type: ignore[operator]
    worst = max(gaps)
    return Judged(f"worst {worst[1]}: {100 * worst[0]:.2f} %", bool(judged) and worst[0] <= 0.05)


def nexting_predictions(spec: Any) -> np.ndarray:
    from horde.core.simulation import Simulation

    sim = Simulation(spec)
    sim.with_metrics = False
    sim.threads = 1
    sim.run(NEXTING_STEPS)
    return np.asarray(sim.learner.engine.prediction(), dtype=np.float64).copy()


Judge = Callable[[str, Any], Judged]
LATTICE = ("every demon vs its exact answer at the start, the prediction demon vs its Monte-Carlo truth",
           "5 % (0.05 for a probability)", judge_lattice)  # fmt: skip
ENDS = "greedy test runs' ends, positive / negative / none"
CHAIN = ("every state's value vs the TD fixed point", "0.05 or 5 % of the value range", judge_chain)
# name: (what is judged, its bound, the judge of one run; None: judged across the dtypes, in `check`)
CRITERIA: dict[str, tuple[str, str, Judge | None]] = {
    **dict.fromkeys(THESIS_LATTICE, LATTICE),
    "experiment3": (ENDS, "at least 98 of 100 positive", judge_counts),
    "experiment3-base": (ENDS, "none (chance)", judge_counts),
    "mountaincar-nexting": ("the represented questions vs the realised returns", "10 % relative", judge_mountaincar),
    "acrobot-offpolicy": ("all 24 questions vs rollouts of the target policy", "0.05 or 5 %", judge_acrobot),
    **dict.fromkeys(CHAINS, CHAIN),
    "baird": ("TD diverged; GTD, GQ, ETD bounded", "predictions within ±100", judge_baird),
    "mountaincar-log": ("position demons vs the log's realised returns", "5 % relative", judge_log),
    "nexting": (f"predictions after {NEXTING_STEPS:,} steps, float32 vs float64", "1e-5 of their scale", None),
}


def _timed(run: Callable[[], Any]) -> tuple[Any, float, float]:
    began, cpu = time.perf_counter(), time.process_time()
    out = run()
    return out, time.perf_counter() - began, time.process_time() - cpu


def check(name: str, dtypes: tuple[str, ...] = DTYPES) -> Row:
    """One scenario in each dtype, judged by its criterion."""
    from horde.scenarios import find_scenario

    criterion, bound, judge = CRITERIA[name]
    spec = find_scenario(name)
    results: dict[str, Judged] = {}
    if judge is None:  # nexting: float32 against float64
        found = {}
        for dtype in dtypes:
            found[dtype], wall, cpu = _timed(lambda dtype=dtype: nexting_predictions(with_dtype(spec, dtype)))
            scale = float(np.abs(found[dtype]).max())
            figure, holds = f"predictions within ±{scale:.4g}", None
            if dtype != "float64" and "float64" in found:
                gap = float(np.abs(found[dtype] - found["float64"]).max()) / float(np.abs(found["float64"]).max())
                figure, holds = f"{gap:.2e} of float64's scale", gap <= NEXTING_BOUND
            results[dtype] = Judged(figure, holds, wall, cpu)
        return Row(name, criterion, bound, results)
    run = judge  # not None past the nexting branch
    for dtype in dtypes:
        judged, wall, cpu = _timed(lambda dtype=dtype: run(name, with_dtype(spec, dtype)))
        results[dtype] = Judged(judged.figure, judged.holds, wall, cpu)
    return Row(name, criterion, bound, results)


def table(rows: list[Row]) -> str:
    """The markdown table: per scenario its criterion and bound, each dtype's result and whether it holds."""

    def verdict(j: Judged | None) -> str:
        if j is None:
            return "-"
        return "n/a" if j.holds is None else ("yes" if j.holds else "**no**")

    lines = ["| scenario | criterion | bound | float64 | float32 | holds (64 / 32) | wall / CPU s (64; 32) |",
             "|---|---|---|---|---|---|---|"]  # fmt: skip
    for r in rows:
        a, b = r.results.get("float64"), r.results.get("float32")
        times = "; ".join(f"{j.wall:.0f} / {j.cpu:.0f}" for j in (a, b) if j is not None)
        lines.append(f"| {r.scenario} | {r.criterion} | {r.bound} | {a.figure if a else '-'} | "
                     f"{b.figure if b else '-'} | {verdict(a)} / {verdict(b)} | {times} |")  # fmt: skip
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--only", nargs="*", default=None, help="scenario names (default: every shipped one)")
    parser.add_argument("--workers", type=int, default=1, help="scenarios run in this many processes at once")
    parser.add_argument("--json", type=Path, default=None, help="also write the rows to this file")
    args = parser.parse_args(argv)
    names = [n for n in CRITERIA if args.only is None or n in args.only]
    unknown = sorted(set(args.only or ()) - set(CRITERIA))
    if unknown:
        parser.error(f"--only: unknown scenario(s) {', '.join(unknown)}; known: {', '.join(CRITERIA)}")
    print(f"load average at the start: {' '.join(f'{x:.1f}' for x in os.getloadavg())}", flush=True)
    rows: list[Row] = []
    if args.workers > 1:
        context = multiprocessing.get_context("spawn")
        with ProcessPoolExecutor(args.workers, mp_context=context) as pool:
            for row in pool.map(check, names):
                print(table([row]).splitlines()[-1], flush=True)
                rows.append(row)
    else:
        for name in names:
            rows.append(check(name))
            print(table(rows[-1:]).splitlines()[-1], flush=True)
    print(f"load average at the end: {' '.join(f'{x:.1f}' for x in os.getloadavg())}")
    print(table(rows))
    if args.json is not None:
        args.json.write_text(json.dumps([asdict(r) for r in rows], indent=1) + "\n")
    return 0 if all(j.holds is not False for r in rows for j in r.results.values()) else 1


if __name__ == "__main__":
    raise SystemExit(main())
