"""What must hold of the textbook studies (issue 25, 2): the book's qualitative findings, asserted on the numbers
of each study file run reduced (fewer runs, episodes or alphas than the shipped figure, which the docstring of
each test says); each still separates the learners it compares by a wide margin.

The studies run in this process (`InProcess`), their results summarised exactly as `horde study` does.
"""

from __future__ import annotations

import itertools
from pathlib import Path

import pytest

from horde.runs.store import Store
from horde.studies.files import load_study_file
from horde.studies.runner import InProcess, create_study, run_study, summarize_study
from horde.studies.spec import AxisSpec
from horde.studies.stats import ConfigSummary

STUDIES = Path(__file__).resolve().parents[2] / "studies"


def run_reduced(tmp_path: Path, name: str, runs: int, episodes: int | None = None,
                axes: dict[str, list[float | str]] | None = None) -> list[ConfigSummary]:  # fmt: skip
    study, base, _ = load_study_file(STUDIES / f"{name}.toml")
    measure = study.measure if episodes is None else study.measure.model_copy(update={"episodes": episodes})
    chosen = [AxisSpec(path=a.path, values=list((axes or {}).get(a.path, a.values))) for a in study.axes]
    study = study.model_copy(update={"runs": runs, "measure": measure, "axes": chosen})
    store = Store(tmp_path / name)
    try:
        record, _ = create_study(store, study, base)
        assert run_study(store, record.id, InProcess()) == "finished"
        return summarize_study(store, record.id)
    finally:
        store.close()


def by(summaries: list[ConfigSummary], **wanted: object) -> list[ConfigSummary]:
    return [s for s in summaries if all(s.axes[p] == v for p, v in wanted.items())]


ALPHAS = [0.1, 0.3, 0.6, 1.0]


@pytest.fixture(scope="module")
def walk19(tmp_path_factory: pytest.TempPathFactory) -> tuple[list[ConfigSummary], list[ConfigSummary]]:
    """Figures 12.3 and 12.8 reduced: 8 runs (shipped: 30), alphas 0.1, 0.3, 0.6, 1 (shipped: eight), lambdas
    0, 0.8 and 1 (shipped: six); the first 10 episodes as shipped."""
    tmp = tmp_path_factory.mktemp("walk19")
    axes: dict[str, list[float | str]] = {"learning.alpha": list(ALPHAS), "learning.lambda": [0.0, 0.8, 1.0]}
    return (
        run_reduced(tmp, "fig-12-3-td-lambda", 8, axes=axes),
        run_reduced(tmp, "fig-12-8-true-online", 8, axes=axes),
    )


def auc(s: ConfigSummary) -> float:
    return float("inf") if s.diverged else s.auc.mean[0]


def test_an_intermediate_lambda_beats_0_and_1_at_its_best_alpha(walk19: tuple) -> None:
    td = walk19[0]
    best = {lam: min(auc(s) for s in by(td, **{"learning.lambda": lam})) for lam in (0.0, 0.8, 1.0)}
    assert best[0.8] < 0.9 * best[0.0] and best[0.8] < 0.9 * best[1.0], best


def test_true_online_td_is_as_good_as_td_at_every_alpha_and_degrades_less(walk19: tuple) -> None:
    """Both demons learn from the same runs (paired). At every alpha and lambda true online TD(lambda)'s error is
    at most 5 % above TD(lambda)'s: at small alpha the two are close (at lambda 0 they are the same learner), so
    "at least as good" holds within that slack, not strictly. The excess is real, not noise, so a paired criterion
    (the difference's 95 % interval not above 0) would fail: over 200 paired runs true online is above by 1.6 %
    at alpha 0.1 (200 runs of 200), 4.6 % at 0.2 and 1.2 % at 0.3 with lambda 0.8, each interval above 0, and the
    book's pseudocode written apart from the engine gives the same (`python -m benchmarks.true_online_paired
    --book`; README, figure 12.8). Where alpha is large it degrades far less: at alpha 1 with lambda 0.8 and 1,
    TD(lambda)'s error is several times true online's (TD(1) is marked diverged)."""
    td, true_online = walk19
    for s in td:
        other = by(true_online, **s.axes)[0]
        assert auc(other) <= 1.05 * auc(s), (s.axes, auc(other), auc(s))
    for lam in (0.8, 1.0):
        big = {"learning.alpha": ALPHAS[-1], "learning.lambda": lam}
        assert auc(by(td, **big)[0]) > 3 * auc(by(true_online, **big)[0]), lam


def test_the_fourier_basis_beats_the_polynomial_of_the_same_order_by_the_end(tmp_path: Path) -> None:
    """Figure 9.5 reduced: 2 runs (shipped: 10), 300 episodes (shipped: 1000), orders 5 and 10 as shipped: the
    Fourier basis' final error is below the polynomial's in every run, and well below on average (measured: 0.11
    against 0.26 at order 5, 0.21 against 0.29 at order 10)."""
    summaries = run_reduced(tmp_path, "fig-9-5-bases", 2, episodes=300)
    for order in (5, 10):
        fourier = by(summaries, **{"features.kind": "fourier", "features.order": order})[0]
        polynomial = by(summaries, **{"features.kind": "polynomial", "features.order": order})[0]
        assert fourier.final.high[0] < polynomial.final.low[0], (order, fourier.final, polynomial.final)
        assert fourier.final.mean[0] < 0.8 * polynomial.final.mean[0], (order, fourier.final, polynomial.final)


def test_td_diverges_on_bairds_star_while_tdc_and_etd_do_not(tmp_path: Path) -> None:
    """Figures 11.5 and 11.6 reduced: 3 runs (shipped: 5), alphas 0.001 and 0.01 (shipped: four), 20 episodes of
    1000 steps as shipped. TD's error grows at both (tenfold at the smaller, ten-thousandfold or marked diverged
    at the larger); TDC ends below its start at both; ETD at 0.001 rises, then turns back down (as
    the expected ETD of figure 11.6 oscillates) and ends at less than half of TD's error."""
    axes: dict[str, list[float | str]] = {"demons.v.alpha": [0.001, 0.01]}
    summaries = run_reduced(tmp_path, "fig-11-5-baird", 3, axes=axes)

    def curve(learner: str, alpha: float) -> list[float]:
        return by(summaries, **{"demons.v.learner": learner, "demons.v.alpha": alpha})[0].curve.mean

    def diverged(learner: str, alpha: float) -> bool:
        return by(summaries, **{"demons.v.learner": learner, "demons.v.alpha": alpha})[0].diverged

    start = curve("td", 0.001)[0]  # sqrt((6 x 3^2 + 12^2) / 7) = 5.32: the first weights' error
    assert 5.0 < start < 5.6
    for alpha in (0.001, 0.01):  # TD's error grows at every checkpoint of the second half, tenfold in all
        td = curve("td", alpha)
        assert all(b > a for a, b in itertools.pairwise(td[5:])) and td[-1] > 10 * start, (alpha, td)
    assert diverged("td", 0.01) or curve("td", 0.01)[-1] > 1e4 * start, curve("td", 0.01)
    for alpha in (0.001, 0.01):
        assert not diverged("gtd", alpha) and curve("gtd", alpha)[-1] < start
    etd = curve("etd", 0.001)
    assert not diverged("etd", 0.001) and etd[-1] < 0.5 * curve("td", 0.001)[-1] and etd[-1] < max(etd), etd
