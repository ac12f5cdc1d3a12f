"""Is true online TD(lambda)'s small excess over TD(lambda) on the 19-state walk at small alpha real? (issue 25, 2)

Figures 12.3 and 12.8 are studies of the two demons of scenarios/random-walk-19.toml, `td` (TD(lambda),
accumulating traces) and `true_online_td`, which learn from the same runs: each run's pair of errors is paired.
This script runs that set-up as the studies measure it (the RMS error over the 19 states, every state alike, after
each of the first 10 episodes, averaged; relative to the RMS of the true values) for many seeds, and prints per
alpha and lambda the mean paired difference (true online minus TD) with its 95 % percentile-bootstrap interval
(`horde.studies.stats.bootstrap_mean`, the studies' bands). An interval
wholly above 0 means true online is really worse there, not by noise.

`--book` runs the same comparison on the book's own pseudocode instead (Sutton & Barto 2018, TD(lambda) with an
accumulating trace, section 12.2, and true online TD(lambda), section 12.5, written out below in plain numpy for
the tabular 19-state walk, its own generator): independent of the engine, it tells whether a difference belongs
to the algorithms or to the engine.

Run: `python -m benchmarks.true_online_paired [--runs 200] [--alphas 0.1,0.3] [--lambdas 0.8] [--book]`.
"""

from __future__ import annotations

import argparse

import numpy as np

from benchmarks.chain_protocols import SCENARIOS
from horde.scenarios import load_scenario
from horde.spec import RunSpec
from horde.studies.stats import bootstrap_mean
from horde.worlds.gymnasium import GymAgent
from horde.worlds.state_values import demon_truth, model_of, predictions_at_states


def paired(alpha: float, lam: float, runs: int, episodes: int) -> tuple[np.ndarray, np.ndarray]:
    """[runs] each run's relative error of true online TD(lambda) minus TD(lambda)'s, and [runs] TD(lambda)'s."""
    base = load_scenario(SCENARIOS / "random-walk-19.toml").model_dump(by_alias=True, exclude_none=True)
    out, td = np.empty(runs), np.empty(runs)
    for run in range(runs):
        data = {**base, "seed": 1000 + run, "learning": {**base["learning"], "alpha": alpha, "lambda": lam}}
        spec = RunSpec.model_validate(data)
        agent = GymAgent(spec, np.random.default_rng([spec.seed, 0]))
        chain = model_of(agent.spec)
        assert chain is not None
        truths = {n: demon_truth(agent.horde, n, chain) for n in ("td", "true_online_td")}
        scale = truths["td"].scale("uniform")  # type: ignore[union-attr]
        errors = {n: 0.0 for n in truths}
        for _ in range(episodes):
            agent.run_episode()
            values = predictions_at_states(agent.horde, agent.learner.horde_state(), chain, list(truths))
            for j, (n, truth) in enumerate(truths.items()):
                errors[n] += truth.rms(values[:, j]) / scale / episodes  # type: ignore[union-attr]
        out[run], td[run] = errors["true_online_td"] - errors["td"], errors["td"]
    return out, td


def book_paired(alpha: float, lam: float, runs: int, episodes: int) -> tuple[np.ndarray, np.ndarray]:
    """As `paired`, on the book's pseudocode: tabular features of states 1..19 (start 10, -1 left, +1 right)."""
    n = 19
    truth = (np.arange(1, n + 1) - 10) / 10  # [N]
    scale = float(np.sqrt(np.mean(truth**2)))
    out, td = np.empty(runs), np.empty(runs)
    for run in range(runs):
        rng = np.random.default_rng(1000 + run)
        w = {"td": np.zeros(n + 2), "true_online": np.zeros(n + 2)}  # states 0..20, the ends stay 0
        error = {name: 0.0 for name in w}
        for _ in range(episodes):
            z = {name: np.zeros(n + 2) for name in w}
            v_old, s = 0.0, 10
            while 0 < s <= n:
                s2 = s + (1 if rng.random() < 0.5 else -1)
                r = -1.0 if s2 == 0 else 1.0 if s2 == n + 1 else 0.0
                # TD(lambda), accumulating trace: z <- gamma lambda z + x; w <- w + alpha delta z
                wt, zt = w["td"], z["td"]
                delta = r + wt[s2] - wt[s]
                zt *= lam
                zt[s] += 1.0
                wt += alpha * delta * zt
                # true online TD(lambda): z <- gamma lambda z + (1 - alpha gamma lambda z.x) x;
                # w <- w + alpha (delta + V - V_old) z - alpha (V - V_old) x; V_old <- V'
                wo, zo = w["true_online"], z["true_online"]
                v, v2 = wo[s], wo[s2]
                delta = r + v2 - v
                dutch = 1.0 - alpha * lam * zo[s]
                zo *= lam
                zo[s] += dutch
                wo += alpha * (delta + v - v_old) * zo
                wo[s] -= alpha * (v - v_old)
                v_old, s = v2, s2
            for name in w:
                error[name] += float(np.sqrt(np.mean((w[name][1 : n + 1] - truth) ** 2))) / scale / episodes
        out[run], td[run] = error["true_online"] - error["td"], error["td"]
    return out, td


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0] if __doc__ else None)
    parser.add_argument("--runs", type=int, default=200)
    parser.add_argument("--episodes", type=int, default=10)
    parser.add_argument("--alphas", default="0.1,0.3")
    parser.add_argument("--lambdas", default="0.8")
    parser.add_argument("--book", action="store_true", help="the book's pseudocode in numpy, not the engine")
    args = parser.parse_args(argv)
    compare = book_paired if args.book else paired
    for lam in (float(x) for x in args.lambdas.split(",")):
        for alpha in (float(x) for x in args.alphas.split(",")):
            d, td = compare(alpha, lam, args.runs, args.episodes)
            mean, low, high = (float(x[0]) for x in bootstrap_mean(d[:, None]))
            print(f"alpha {alpha} lambda {lam}: TD {td.mean():.4f}, true online - TD = {mean:+.4f} [{low:+.4f}, "
                  f"{high:+.4f}] ({100 * mean / td.mean():+.1f} %; "
                  f"95 %, {len(d)} runs; "
                  f"true online above in {int((d > 0).sum())} of them)")  # fmt: skip
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
