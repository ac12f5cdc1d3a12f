"""The `horde` command: `horde run | scenarios | serve | bench | study`."""

from __future__ import annotations

import argparse
import json
import math
import sys
from collections.abc import Sequence
from pathlib import Path

from horde.bench import add_bench_parser
from horde.core.batch import run_protocol_batched
from horde.core.experiment import ProtocolResult
from horde.progress import ProgressBar
from horde.scenarios import ScenarioError, list_scenarios, load_scenario
from horde.spec import RunSpec
from horde.studies.cli import add_study_parser


def _number(value: float | None, digits: int = 3) -> str:
    return "-" if value is None or not math.isfinite(value) else f"{value:.{digits}f}"


def format_results(spec: RunSpec, result: ProtocolResult) -> str:
    """The results table of `horde run`: one row per demon, thesis numbers beside ours."""
    header = ("demon", "prediction", "truth (MC)", "± stderr", "error", "error %", "thesis")
    rows = []
    for demon in result.demons:
        relative = 100 * demon.error / abs(demon.truth) if demon.error is not None and demon.truth else None
        rows.append(
            (
                demon.name,
                _number(demon.prediction),
                _number(demon.truth),
                _number(demon.truth_stderr),
                _number(demon.error),
                _number(relative, 1),
                _number(demon.thesis),
            )
        )
    widths = [max(len(r[i]) for r in [header, *rows]) for i in range(len(header))]
    lines = ["  ".join(cell.rjust(w) if i else cell.ljust(w) for i, (cell, w) in enumerate(zip(r, widths, strict=True)))
             for r in [header, *rows]]  # fmt: skip
    lines.insert(1, "  ".join("-" * w for w in widths))
    for demon in result.demons:
        if demon.counts is not None:
            c = demon.counts
            lines.append("")
            lines.append(f"test runs of {demon.name}: positive {c.positive}, negative {c.negative}, none {c.none}")
            if result.thesis_counts:
                t = result.thesis_counts
                lines.append(f"thesis:              positive {t.positive}, negative {t.negative}, none {t.none}")
    protocol = spec.protocol
    lines.append("")
    lines.append(
        f"{protocol.trials} trials x {protocol.episodes} episodes (max {spec.grid.max_steps} steps), "
        f"{result.steps} steps in {result.seconds:.1f} s ({result.steps_per_second:,.0f} steps/s); "
        f"truth: {protocol.evaluation.rollouts} rollouts per trial, capped at {result.rollout_cap} steps"
    )
    return "\n".join(lines)


def _override(spec: RunSpec, trials: int | None, episodes: int | None, seed: int | None) -> RunSpec:
    protocol = spec.protocol.model_copy(
        update={k: v for k, v in {"trials": trials, "episodes": episodes}.items() if v is not None}
    )
    data = spec.model_dump(by_alias=True)
    data["protocol"] = protocol.model_dump(by_alias=True)
    if seed is not None:
        data["seed"] = seed
    return RunSpec.model_validate(data)


def cmd_run(args: argparse.Namespace) -> int:
    if args.workers is not None and args.workers < 0:
        print(f"error: --workers: {args.workers} is below 0 (0 or none: one per core)", file=sys.stderr)
        return 2
    try:
        spec = load_scenario(args.scenario)
        spec = _override(spec, args.trials, args.episodes, args.seed)
    except ScenarioError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    except ValueError as exc:
        print(f"error: {args.scenario}: {exc}", file=sys.stderr)
        return 2
    progress = ProgressBar(spec.name or Path(args.scenario).stem) if not args.quiet else None
    if args.log:
        return _run_log(spec, args)
    if spec.world.kind == "gymnasium":
        return _run_gymnasium(spec, args, progress)
    # None or 0: one process per core this process may use (threads.share: HORDE_THREADS caps it)
    result = run_protocol_batched(spec, args.workers or None, progress)
    print(format_results(spec, result))
    if args.json:
        Path(args.json).write_text(json.dumps([d.as_dict() for d in result.demons], indent=2) + "\n")
    return 0


def _run_gymnasium(spec: RunSpec, args: argparse.Namespace, progress: ProgressBar | None) -> int:
    """`horde run` on a Gymnasium world: learn, then each prediction beside its realised return."""
    from horde.worlds.protocol import format_gym_results, run_gym_protocol

    result = run_gym_protocol(spec, progress)
    print(format_gym_results(spec, result))
    if args.json:
        Path(args.json).write_text(json.dumps([d.as_dict() for d in result.demons], indent=2) + "\n")
    return 0


def _run_log(spec: RunSpec, args: argparse.Namespace) -> int:
    """`horde run --log FILE`: the scenario's stream world learns a recorded log at full speed."""
    from horde.worlds.log_run import format_log_result, learn_log

    path = Path(args.log)
    if spec.world.kind != "stream":
        print(
            f"error: {args.scenario}: world.kind: --log needs a stream world, not {spec.world.kind!r}", file=sys.stderr
        )
        return 2
    progress = ProgressBar(path.name, unit="records") if not args.quiet else None
    try:
        result = learn_log(spec, path, progress)
    except (OSError, ValueError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    print(format_log_result(path, result))
    if args.strip:
        from horde.worlds.log_run import strip_chart

        demons = args.strip_demons.split(",") if args.strip_demons else [d.name for d in spec.demons[:3]]
        sensors = args.strip_sensors.split(",") if args.strip_sensors else spec.world.sensor_names()[:3]
        try:
            strip_chart(spec, result, Path(args.strip), sensors, demons)
        except ValueError as exc:
            print(f"error: {exc}", file=sys.stderr)
            return 2
        print(f"strip chart: {args.strip}")
    if args.json:
        rows = [{"name": d.name, "prediction": d.prediction, "mean_prediction": d.mean_prediction,
                 "mean_return": d.mean_return} for d in result.demons]  # fmt: skip
        Path(args.json).write_text(json.dumps(rows, indent=2) + "\n")
    return 0


def cmd_scenarios(args: argparse.Namespace) -> int:
    try:
        scenarios = list_scenarios(Path(args.dir) if args.dir else None)
    except ScenarioError as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 2
    width = max((len(s.name) for s in scenarios), default=0)
    for scenario in scenarios:
        print(f"{scenario.name.ljust(width)}  {scenario.description}")
    return 0


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="horde", description="Horde Lab: many predictions learned at once.")
    sub = parser.add_subparsers(dest="command", required=True)

    run = sub.add_parser("run", help="run a scenario's protocol and compare predictions with the truth")
    run.add_argument("scenario", help="a scenario file, e.g. scenarios/experiment1.toml")
    run.add_argument("--trials", type=int, help="override the number of trials")
    run.add_argument("--episodes", type=int, help="override the episodes per trial")
    run.add_argument("--seed", type=int, help="override the seed")
    run.add_argument("--json", metavar="PATH", help="also write the results as JSON")
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    run.add_argument("--log", metavar="FILE", help="a stream scenario: learn a CSV or Parquet log at full speed")
    run.add_argument("--strip", metavar="PNG", help="with --log: draw sensors, predictions and realised returns")
    run.add_argument("--strip-sensors", metavar="A,B", help="the sensors to draw (default: the first three)")
    run.add_argument("--strip-demons", metavar="A,B", help="the demons to draw (default: the first three)")
    run.add_argument(
        "--workers", type=int, default=None, metavar="N",
        help="run the trials in N processes at once (default, or 0: one per core this process may use; "
        "HORDE_THREADS caps it); the results are the same whatever N",
    )  # fmt: skip
    run.set_defaults(func=cmd_run)

    scenarios = sub.add_parser("scenarios", help="list the scenarios with a one-line description each")
    scenarios.add_argument("--dir", help="folder of scenario files (default: scenarios/)")
    scenarios.set_defaults(func=cmd_scenarios)

    add_bench_parser(sub)
    add_study_parser(sub)

    try:
        from horde.server.cli_serve import add_serve_parser
    except ImportError:  # the server's dependencies are not installed
        pass
    else:
        add_serve_parser(sub)
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    args = build_parser().parse_args(argv)
    return int(args.func(args))  # every subcommand sets func


if __name__ == "__main__":
    sys.exit(main())
