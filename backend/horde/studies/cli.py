"""`horde study studies/NAME.toml`: run a parameter study with a progress bar; results, JSON and plots."""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
from pathlib import Path

from horde.progress import ProgressBar
from horde.runs.errors import NotFoundError
from horde.runs.store import Store
from horde.scenarios import ScenarioError
from horde.studies.export import curves_csv, results_csv, results_json
from horde.studies.files import load_study_file
from horde.studies.local_ray import LocalRay
from horde.studies.runner import (
    Executor,
    InProcess,
    RayExecutor,
    create_study,
    load_study,
    run_study,
    summarize_study,
)
from horde.studies.spec import label, study_warnings
from horde.studies.stats import ConfigSummary

TABLE_ROWS = 20


def _number(value: float) -> str:
    return f"{value:.4f}" if math.isfinite(value) else "-"


def format_table(summaries: list[ConfigSummary], rows: int = TABLE_ROWS) -> str:
    """The configurations by final relative error, best first (the first `rows`)."""
    ranked = sorted(summaries, key=lambda s: (s.diverged or not math.isfinite(s.final.mean[0]), s.final.mean[0]))
    lines = [f"{'':2}{'configuration':50} {'runs':>4} {'error':>8} {'95% CI':>19} {'AUC':>8}"]
    for s in ranked[:rows]:
        ci = f"[{_number(s.final.low[0])}, {_number(s.final.high[0])}]"
        mark = "* " if s.best else "  "
        error, auc = _number(s.final.mean[0]), _number(s.auc.mean[0])
        note = "  diverged" if s.diverged else ""
        lines.append(f"{mark}{label(s.axes)[:50]:50} {s.runs:>4} {error:>8} {ci:>19} {auc:>8}{note}")
    if len(ranked) > rows:
        lines.append(f"  ... {len(ranked) - rows} more (see --json)")
    lines.append("error: final relative error (RMSE / RMS of the exact answers, mean over demons); * best")
    if any(s.diverged for s in summaries):
        lines.append("diverged: a run's error was non-finite or above 1e6, or the engine froze a demon: not a fit")
    return "\n".join(lines)


def cmd_study(args: argparse.Namespace) -> int:
    store = Store(Path(args.data or os.environ.get("HORDE_DATA") or ".horde"))
    try:
        if args.resume:
            record = store.get_study(args.resume)
            if record is None:
                raise NotFoundError(f"no study {args.resume!r} in {store.path}")
            study_id, name = record.id, record.name or record.id
            print(f"resuming study {study_id} ({name})", file=sys.stderr)
        elif args.study:
            study, base, _ = load_study_file(args.study)
            updates = {k: v for k, v in {"runs": args.runs}.items() if v is not None}
            if args.episodes is not None:
                updates["measure"] = study.measure.model_copy(update={"episodes": args.episodes})
            study = study.model_copy(update=updates) if updates else study
            record, _ = create_study(store, study, base)
            study_id, name = record.id, record.name or record.id
            print(f"study {study_id} ({name}): {record.tasks} tasks; resume with --resume {study_id}", file=sys.stderr)
        else:
            print("error: give a study file or --resume ID", file=sys.stderr)
            return 2
    except (ScenarioError, NotFoundError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        store.close()
        return 2
    except ValueError as exc:  # an override that does not validate
        print(f"error: {args.study}: {exc}", file=sys.stderr)
        store.close()
        return 2
    for warning in study_warnings(load_study(store, study_id)[2]):
        print(f"warning: {warning}", file=sys.stderr)
    address = args.address or os.environ.get("HORDE_RAY_ADDRESS") or None
    local = LocalRay(args.workers or None) if not args.local and address is None else None
    progress = None if args.quiet else ProgressBar(name, unit="tasks")
    try:
        status = run_study(store, study_id, _executor(args.local, address, local), progress)
        summaries = summarize_study(store, study_id)
    except Exception as exc:  # a task that failed: the study keeps its finished tasks and can be resumed
        print(f"\nerror: study {study_id} failed: {type(exc).__name__}: {exc}", file=sys.stderr)
        print(
            f"its finished tasks are kept; after a fix, resume with: horde study --resume {study_id}", file=sys.stderr
        )
        return 1
    finally:
        RayExecutor.shutdown()
        if local is not None:
            local.stop()
        store.close()
    if status != "finished":
        print(f"\nstudy {study_id} {status}; finish it with: horde study --resume {study_id}", file=sys.stderr)
    if not summaries:
        return 1
    print(format_table(summaries))
    write_outputs(summaries, args)
    return 0 if status == "finished" else 1


def _executor(here: bool, address: str | None, local: LocalRay | None) -> Executor:
    """One task after the other here, or Ray: the cluster at `address`, else a Ray of this process's own (loopback
    only, token authentication: its settings go to this process's environment before Ray is imported)."""
    if here:
        return InProcess()
    if local is not None:
        os.environ.update(local.env())
        return RayExecutor(local.address())
    return RayExecutor(str(address))


def write_outputs(summaries: list[ConfigSummary], args: argparse.Namespace) -> None:
    """--json, --csv and --plots: the results as files."""
    if args.json:
        Path(args.json).write_text(json.dumps(results_json(summaries), indent=2) + "\n")
    if args.csv:
        folder = Path(args.csv)
        folder.mkdir(parents=True, exist_ok=True)
        (folder / "results.csv").write_text(results_csv(summaries))
        (folder / "curves.csv").write_text(curves_csv(summaries))
        print(f"csv: {folder / 'results.csv'}, {folder / 'curves.csv'}", file=sys.stderr)
    if args.plots:
        from horde.studies.plots import write_plots

        files = write_plots(summaries, Path(args.plots), args.x, args.group)
        print(f"plots: {', '.join(str(f) for f in files)}", file=sys.stderr)


def add_study_parser(sub: argparse._SubParsersAction) -> None:
    study = sub.add_parser("study", help="run a parameter study (axes x runs) on Ray; results, JSON, plots")
    study.add_argument("study", nargs="?", help="a study file, e.g. studies/stepsizes.toml")
    study.add_argument("--resume", metavar="ID", help="resume a stored study: only unfinished tasks run")
    study.add_argument("--address", help="join this Ray cluster (default: HORDE_RAY_ADDRESS, else Ray on this machine)")
    study.add_argument("--workers", type=int, metavar="N", help="CPUs of the local Ray (default: every core)")
    study.add_argument("--local", action="store_true", help="run the tasks in this process, one at a time, without Ray")
    study.add_argument("--runs", type=int, help="override the runs per configuration")
    study.add_argument("--episodes", type=int, help="override the training episodes per run")
    study.add_argument(
        "--json",
        metavar="PATH",
        help="write one object per configuration (axes, runs, per demon error, ci_low, ci_high)",
    )
    study.add_argument(
        "--csv",
        metavar="DIR",
        help="write results.csv (a row per configuration and demon) and curves.csv (the "
        "learning curves: a row per configuration, demon and checkpoint)",
    )
    study.add_argument("--plots", metavar="DIR", help="write learning and sensitivity curves (PNG and SVG)")
    study.add_argument("--x", metavar="PATH", help="the axis along the sensitivity curves (default: the first numeric)")
    study.add_argument(
        "--group", metavar="PATH", help="one sensitivity curve per value of this axis (default: the last)"
    )
    study.add_argument("--data", metavar="DIR", help="the data directory of the store (default: HORDE_DATA or .horde)")
    study.add_argument("--quiet", action="store_true", help="no progress bar")
    study.set_defaults(func=cmd_study)
