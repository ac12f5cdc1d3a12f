"""Parameter studies: axes over a RunSpec, one task per configuration x run (on Ray), results with
95 % bootstrap confidence intervals, plots and exports."""

from horde.studies.runner import InProcess, RayExecutor, create_study, run_study, summarize_study
from horde.studies.spec import AxisSpec, Configuration, MeasureSpec, SampleSpec, StudySpec, expand
from horde.studies.stats import bootstrap_mean
from horde.studies.task import run_task

__all__ = [
    "AxisSpec",
    "Configuration",
    "InProcess",
    "MeasureSpec",
    "RayExecutor",
    "SampleSpec",
    "StudySpec",
    "bootstrap_mean",
    "create_study",
    "expand",
    "run_study",
    "run_task",
    "summarize_study",
]
