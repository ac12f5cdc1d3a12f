"""The step size of the thesis's GQ(lambda) control demon `base`, chosen by experiment.

The thesis (Planting 2012) gives no step size for its experiments. This sweep varies `base`'s own `alpha`
(nothing else: the other demons keep theirs) over the whole protocol of every shipped scenario with such a
demon (`experiment1`, the five `experiment2-*`, `experiment3` and `experiment3-base`) and measures, per
trial, what `horde run` measures (each demon's prediction at the start, its Monte-Carlo truth with the
same generator, the greedy test runs' ends) and, on the lattice scenarios, each demon's exact answer at the
start under its learned target policy (`core.evaluate.exact`, as `exact_check` does).

`python -m horde.studies.base_alpha --alphas 0.1 0.03 0.02 0.01 0.005 --json docs/studies/base-alpha.json`
runs it (in `--workers` processes) and appends to the JSON file (one object per scenario x alpha);
`--plot docs/studies/base-alpha.png` draws the sensitivity figure from that file (docs/autostep-exact.md).
"""

from __future__ import annotations

import argparse
import json
import time
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path
from typing import Any

import numpy as np

from horde.core.evaluate import exact, monte_carlo
from horde.core.experiment import learn, start_point
from horde.scenarios import find_scenario
from horde.spec import Counts, RunSpec
from horde.studies.exact_check import DemonCheck
from horde.studies.task import has_exact_answers

SCENARIOS = [
    "experiment1",
    "experiment2-large",
    "experiment2-none",
    "experiment2-small",
    "experiment2-start",
    "experiment2-whole",
    "experiment3",
    "experiment3-base",
]


def with_base_alpha(spec: RunSpec, alpha: float) -> RunSpec:
    """The spec with demon `base`'s own alpha set and nothing else changed (validated again)."""
    body = spec.model_dump(by_alias=True)
    for demon in body["demons"]:
        if demon["name"] == "base":
            demon["alpha"] = alpha
    return RunSpec.model_validate(body)


def trial(spec: RunSpec, number: int, exact_answers: bool) -> dict[str, Any]:
    """One trial as `horde run` runs it (`experiment.run_trial`: learn, Monte-Carlo truth with the trial's
    generator, test runs), plus the exact answers at the start (which use no random numbers, so the
    Monte-Carlo numbers are `horde run`'s)."""
    began, cpu = time.perf_counter(), time.process_time()
    sim, rng, episodes = learn(spec, number)
    learned_wall, learned_cpu = time.perf_counter() - began, time.process_time() - cpu
    horde, state = sim.horde, sim.horde_state
    start = start_point(spec)
    predictions = sim.predictions_at(*start)
    exacts: dict[str, float] = {}
    if exact_answers:
        for name in horde.names:
            lattice = exact(horde, state, name)
            here = int(np.argmin(np.hypot(lattice.x - start[0], lattice.y - start[1])))
            exacts[name] = float(lattice.value[here])
    began, cpu = time.perf_counter(), time.process_time()
    evaluation = spec.protocol.evaluation
    truths: dict[str, float] = {}
    if evaluation.rollouts > 0:
        for name in evaluation.demons if evaluation.demons is not None else horde.names:
            truths[name] = monte_carlo(horde, state, name, start, evaluation.rollouts, evaluation.cap, rng).mean
    counts = None
    if spec.protocol.test is not None:
        learning = np.array([d.reset == "episode" for d in horde.demon_specs])
        tally = {1.0: 0, -1.0: 0, 0.0: 0}
        for _ in range(spec.protocol.test.runs):
            sim.new_episode()
            tally[sim.run_episode(behaviour=spec.protocol.test.behaviour, learning=learning).terminal_sign] += 1
        counts = Counts(positive=tally[1.0], negative=tally[-1.0], none=tally[0.0]).model_dump()
    return {
        "predictions": predictions,
        "exact": exacts,
        "truths": truths,
        "counts": counts,
        "episodes": episodes,
        "steps": sim.total_steps,
        # learning plus the Monte-Carlo truth and test runs: what `horde run` spends (not the exact solves)
        "wall": learned_wall + time.perf_counter() - began,
        "cpu": learned_cpu + time.process_time() - cpu,
    }


def sweep_one(scenario: str, alpha: float, seed: int | None = None) -> dict[str, Any]:
    """One scenario's whole protocol with `base`'s alpha set (and its seed, if given: other trials' draws)."""
    spec = with_base_alpha(find_scenario(scenario), alpha)
    if seed is not None:
        spec = spec.model_copy(update={"seed": seed})
    lattice = has_exact_answers(spec, [d.name for d in spec.demons])
    trials = [trial(spec, n, lattice) for n in range(spec.protocol.trials)]
    return {"scenario": scenario, "alpha": alpha, "seed": spec.seed, "trials": trials}


def load(path: Path) -> list[dict[str, Any]]:
    """The sweep's results, one object per scenario x alpha x seed (the last of each, if run twice)."""
    found: dict[tuple[str, float, int | None], dict[str, Any]] = {}
    for line in path.read_text().splitlines():
        if line.strip():
            item = json.loads(line)
            item.setdefault("seed", find_scenario(item["scenario"]).seed)  # written before --seeds
            found[(item["scenario"], item["alpha"], item["seed"])] = item
    return sorted(found.values(), key=lambda r: (SCENARIOS.index(r["scenario"]), r["seed"], -r["alpha"]))


def exact_checks(result: dict[str, Any]) -> list[DemonCheck]:
    """Every demon of a lattice scenario against its exact answer at the start, per trial (as `exact_check`)."""
    trials = result["trials"]
    if not trials[0]["exact"]:
        return []
    spec = find_scenario(result["scenario"])
    out = []
    for demon in spec.demons:
        answers = np.array([t["exact"][demon.name] for t in trials])
        predictions = np.array([t["predictions"][demon.name] for t in trials])
        probability = demon.cumulant == 0 and bool(np.all((answers >= -1e-9) & (answers <= 1 + 1e-9)))
        out.append(
            DemonCheck(result["scenario"], demon.name, demon.learner, "constant", probability, answers, predictions)
        )
    return out


def thesis_criterion(result: dict[str, Any]) -> str:
    """The scenario's own criterion (README, the thesis experiments): the prediction demon's mean prediction
    against its mean Monte-Carlo truth (5 % for steps, 0.05 for a probability), or the greedy test runs'
    ends summed over trials."""
    trials = result["trials"]
    if trials[0]["counts"] is not None:
        total = {k: sum(t["counts"][k] for t in trials) for k in ("positive", "negative", "none")}
        return f"{total['positive']}/{total['negative']}/{total['none']}"
    (name,) = [n for n in trials[0]["truths"] if n != "base"] or ["base"]
    prediction = float(np.mean([t["predictions"][name] for t in trials]))
    truth = float(np.mean([t["truths"][name] for t in trials]))
    if name == "critical":
        return f"{name} {prediction:.3f} vs {truth:.3f}: {abs(prediction - truth):.3f}"
    return f"{name} {prediction:.2f} vs {truth:.2f}: {100 * abs(prediction - truth) / abs(truth):.2f} %"


def standard_error(check: DemonCheck) -> float:
    """The standard error of the error of the mean over trials, relative to the mean exact answer: the noise
    of the statistic the bound judges (from the spread of the per-trial gaps)."""
    gap = check.prediction - check.exact
    return float(gap.std(ddof=1) / np.sqrt(len(gap)) / abs(check.exact.mean()))


def meets(result: dict[str, Any]) -> bool:
    """The rule of the choice, on one scenario: `base`'s mean over trials within 5 % of the exact answer, with
    a standard error of at most half that bound (the bound two standard errors away, so that the mean would
    hold for about 95 % of other seeds, not by the luck of these); every other demon
    within its bound of the exact answer; the thesis criterion: the prediction demon's mean within 5 % (0.05
    for a probability) of its Monte-Carlo truth, or at least 98 of 100 greedy test runs positive in
    `experiment3`."""
    trials = result["trials"]
    if trials[0]["counts"] is not None:
        return result["scenario"] != "experiment3" or sum(t["counts"]["positive"] for t in trials) >= 98
    checks = exact_checks(result)
    base = next(c for c in checks if c.demon == "base")
    if not (base.holds and standard_error(base) <= base.tolerance / 2 and all(c.holds for c in checks)):
        return False
    for name in trials[0]["truths"]:
        check = next(c for c in checks if c.demon == name)
        prediction = np.mean([t["predictions"][name] for t in trials])
        truth = np.mean([t["truths"][name] for t in trials])
        gap = abs(prediction - truth) if check.probability else abs(prediction - truth) / abs(truth)
        if gap > check.tolerance:
            return False
    return True


def choose(results: list[dict[str, Any]]) -> float:
    """The largest swept alpha that meets the rule (`meets`) on every scenario swept."""
    alphas = sorted({r["alpha"] for r in results}, reverse=True)
    good = [a for a in alphas if all(meets(r) for r in results if r["alpha"] == a)]
    if not good:
        raise ValueError("no swept alpha meets the rule")
    return good[0]


def label(result: dict[str, Any]) -> str:
    """The scenario's name, and the seed when it is not the scenario's own."""
    seed = result.get("seed")
    own = seed is None or seed == find_scenario(result["scenario"]).seed
    return result["scenario"] if own else f"{result['scenario']} (seed {seed})"


def markdown(results: list[dict[str, Any]]) -> str:
    """Per scenario x alpha: `base`'s exact error (of the mean over trials, and the per-trial range), the other
    demons' exact errors, the thesis criterion, and the protocol's time as `horde run` spends it."""
    lines = [
        "| scenario | base alpha | base exact (mean) | base prediction (mean) | base error | its standard error | "
        "base per trial | other demons (exact) | thesis criterion | meets the rule | steps | wall / CPU s |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for r in results:
        checks = {c.demon: c for c in exact_checks(r)}
        trials = r["trials"]
        wall, cpu = sum(t["wall"] for t in trials), sum(t["cpu"] for t in trials)
        steps = sum(t["steps"] for t in trials)
        base = checks.get("base")
        others = "; ".join(
            f"{c.demon} {c.error:.3g}" if c.probability else f"{c.demon} {100 * c.error:.2f} %"
            for n, c in checks.items()
            if n != "base"
        )
        if base is None:
            cells = ["", "", "", "", ""]
        else:
            cells = [
                f"{base.exact.mean():.4f}",
                f"{base.prediction.mean():.4f}",
                f"{100 * base.error:.2f} %" + ("" if base.holds else " **no**"),
                f"{100 * standard_error(base):.1f} %",
                f"{100 * base.errors.min():.1f} to {100 * base.errors.max():.0f} %",
            ]
        lines.append(
            f"| {label(r)} | {r['alpha']:g} | {' | '.join(cells)} | {others} | {thesis_criterion(r)} | "
            f"{'yes' if meets(r) else '**no**'} | {steps:,} | {wall:.1f} / {cpu:.1f} |"
        )
    return "\n".join(lines)


def _intervals(checks: list[DemonCheck]) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Mean per-trial error of each check and its 95 % bootstrap interval (mean, low, high)."""
    from horde.studies.stats import bootstrap_mean

    bounds = np.array([[float(v) for v in bootstrap_mean(c.errors)] for c in checks])
    return bounds[:, 0], bounds[:, 1], bounds[:, 2]


def _base_panel(axis: Any, results: list[dict[str, Any]]) -> None:
    """`base`'s error at the start against its alpha: per trial (mean, interval) and of the mean over trials."""
    families = {"experiment1": "experiment1", "experiment2-large": "experiment2-* (one base for all five)"}
    for number, (scenario, title) in enumerate(families.items()):
        rows = [r for r in results if r["scenario"] == scenario]
        alphas = np.array([r["alpha"] for r in rows])
        checks = [next(c for c in exact_checks(r) if c.demon == "base") for r in rows]
        mean, low, high = _intervals(checks)
        colour = f"C{number}"
        axis.errorbar(alphas, 100 * mean, yerr=[100 * (mean - low), 100 * (high - mean)], color=colour,
                      marker="o", capsize=3, label=f"{title}: per trial (mean, 95 % bootstrap interval)")  # fmt: skip
        axis.plot(alphas, 100 * np.array([c.error for c in checks]), color=colour, marker="s", linestyle="--",
                  label=f"{title}: of the mean over trials")  # fmt: skip
    axis.axhline(5, color="black", linewidth=1, linestyle=":", label="the bound, 5 %")
    axis.set_yscale("log")
    axis.set_xlabel("base's alpha (divided by its 5 active features per step)")
    axis.set_ylabel("base: |prediction - exact| / |exact| at the start (%)")
    axis.set_title("base (GQ(lambda) control demon), 10 trials x 10,000 episodes", fontsize=10)


def _prediction_panel(axis: Any, results: list[dict[str, Any]]) -> None:
    """The prediction demons' exact errors against base's alpha, one curve per scenario."""
    for number, scenario in enumerate(SCENARIOS[:6]):
        rows = [r for r in results if r["scenario"] == scenario]
        if not rows:
            continue
        alphas = np.array([r["alpha"] for r in rows])
        checks = [next(c for c in exact_checks(r) if c.demon != "base") for r in rows]
        unit = "absolute x 100" if checks[0].probability else "%"
        mean, low, high = _intervals(checks)
        axis.errorbar(alphas * (1 + 0.015 * (number - 2.5)), 100 * mean,
                      yerr=[100 * (mean - low), 100 * (high - mean)], marker="o", capsize=3, color=f"C{number}",
                      label=f"{scenario} {checks[0].demon} ({unit})")  # fmt: skip
    axis.axhline(5, color="black", linewidth=1, linestyle=":", label="the bound (5 %, or 0.05)")
    axis.set_xlabel("base's alpha (the prediction demons keep alpha 0.05)")
    axis.set_ylabel("prediction demon's error per trial (%, or absolute x 100)")
    axis.set_title("prediction demons, under base's learned policy (95 % bootstrap intervals)", fontsize=10)


def plot(results: list[dict[str, Any]], path: Path) -> None:
    """The sensitivity figure: `base`'s error at the start against its alpha (left; the error of the mean
    over trials, which the bound judges, and the mean per-trial error with its 95 % bootstrap interval), and
    the prediction demons' exact errors (right), one curve per scenario."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from matplotlib import ticker

    fig, (left, right) = plt.subplots(1, 2, figsize=(13, 4.8))
    _base_panel(left, results)
    _prediction_panel(right, results)
    chosen = choose(results)
    ticks = sorted({r["alpha"] for r in results})
    for axis, columns in ((left, 1), (right, 2)):
        axis.axvline(chosen, color="grey", linewidth=6, alpha=0.25, label=f"chosen: {chosen:g}")
        axis.set_xscale("log")
        axis.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.3), ncol=columns)
        axis.grid(True, which="major", alpha=0.3)
        axis.set_xticks(ticks, [f"{a:g}" for a in ticks], rotation=45)
        axis.minorticks_off()
        axis.set_xlim(ticks[0] / 1.25, ticks[-1] * 1.25)
    left.yaxis.set_major_formatter(ticker.FuncFormatter(lambda v, _: f"{v:g}"))
    fig.tight_layout()
    fig.savefig(path, dpi=110, bbox_inches="tight")
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--alphas", type=float, nargs="*", default=[0.1, 0.03, 0.02, 0.01, 0.005])
    parser.add_argument("--only", nargs="*", default=SCENARIOS)
    parser.add_argument("--seeds", type=int, nargs="*", default=[None], help="other seeds (default: the scenario's)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--json", type=Path, default=None, help="append one JSON object per line to this file")
    parser.add_argument("--report", type=Path, default=None, help="no sweep: the table and figure from this file")
    parser.add_argument("--plot", type=Path, default=None, help="with --report: write the figure here")
    args = parser.parse_args()
    if args.report is not None:
        results = load(args.report)
        print(markdown(results))
        print(f"\nchosen: {choose(results):g} (the largest alpha that meets the rule on every scenario)")
        if args.plot is not None:
            plot(results, args.plot)
        return
    jobs = [(s, a, seed) for seed in args.seeds for a in args.alphas for s in args.only]
    with ProcessPoolExecutor(args.workers) as pool:
        for done in as_completed([pool.submit(sweep_one, s, a, seed) for s, a, seed in jobs]):
            found = done.result()
            wall = sum(t["wall"] for t in found["trials"])
            cpu = sum(t["cpu"] for t in found["trials"])
            name = f"{found['scenario']} seed {found['seed']} alpha {found['alpha']}"
            print(f"{name}: {wall:.1f} s wall, {cpu:.1f} s CPU", flush=True)
            if args.json is not None:
                with args.json.open("a") as out:
                    out.write(json.dumps(found) + "\n")


if __name__ == "__main__":
    main()
