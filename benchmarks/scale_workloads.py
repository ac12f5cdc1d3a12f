"""The Horde-scale workloads of `horde bench`: nexting, off-policy and control, over the sensor stream.

Each workload is a `Layout` of blocks plus the per-step inputs of `scale.step` (the action, its
behaviour probability, the next features, cumulants, continuations, importance ratios and given
policies), drawn from `sensors.make_stream` and one seeded generator, so that every engine (the
compiled one, the numpy path, the plain reference) sees the same transitions.

* nexting: D TD(lambda) or GTD(lambda) demons on-policy, one block per timescale (gamma 0, 0.5, 0.75,
  0.875, 0.9375): all demons of a timescale share one trace.
* off_policy: D GTD(lambda) demons about 300 stochastic target policies under a uniform behaviour. Each
  policy has one timescale and about D / 300 questions, which share its trace (a trace class); the
  policies of one timescale form one block (60 classes of about 27 demons for D = 8000), so that a
  feature's weights for all of them are contiguous.
* control: D GQ(lambda) demons over 4 x 6065 state-action features, each with a softmax target policy
  over its own action values (rho of its own: a trace class per demon), one block per timescale.

Cumulants are the sensors' readings or readings above a threshold (`sensors.threshold_cumulants`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from benchmarks import sensors
from horde.core.scale import TRACE_CUT, A, Block, Layout

LAMBDA = 0.9
ALPHA = 0.1  # divided by the 457 active features
ALPHA_W = 0.001
POLICIES = 300


@dataclass(frozen=True)
class Step:
    """The inputs of one `scale.step` call."""

    action: int
    b_prob: float
    x_tp1: np.ndarray  # [k]
    r_tp1: np.ndarray  # [D]
    z_tp1: np.ndarray  # [D]
    gamma_tp1: np.ndarray  # [C]
    rho_t: np.ndarray  # [C]
    pi_tp1: np.ndarray | None  # [C, A]


@dataclass(frozen=True)
class ScaleWorkload:
    """A layout and the stream it learns from.

    Attributes:
        name: "nexting", "off_policy" or "control".
        layout: the blocks.
        stream: the sensor stream (step 0 is observed first).
        sensor, threshold: [D] what each demon's cumulant reads.
        gamma: [C] each trace class's (constant) continuation.
        policy_sensor, policy_bias, policy_gain: [C], [C, A], [C, A] the given target policies (off_policy):
            pi(. | s) = softmax(bias + gain * reading of the policy's sensor).
        actions: [T] the behaviour's actions (uniform, drawn from the workload's generator).
    """

    name: str
    layout: Layout
    stream: sensors.Stream
    sensor: np.ndarray
    threshold: np.ndarray
    gamma: np.ndarray
    actions: np.ndarray
    policy_sensor: np.ndarray | None = None
    policy_bias: np.ndarray | None = None
    policy_gain: np.ndarray | None = None

    @property
    def steps(self) -> int:
        return self.stream.steps - 1

    def target(self, t: int) -> np.ndarray | None:
        """[C, A] the given target policies at step t (None on-policy / for own-value blocks)."""
        if self.policy_sensor is None or self.policy_bias is None or self.policy_gain is None:
            return None
        z = self.policy_bias + self.policy_gain * self.stream.readings[t, self.policy_sensor][:, None]  # [B, A]
        z = np.exp(z - z.max(axis=1, keepdims=True))
        return z / z.sum(axis=1, keepdims=True)

    def step(self, t: int) -> Step:
        """The transition from stream step t to t + 1."""
        action = int(self.actions[t])
        b_prob = 1.0 if self.name == "nexting" else 1.0 / A
        pi_t, pi_tp1 = self.target(t), self.target(t + 1)
        rho = np.ones(self.layout.num_classes) if pi_t is None else pi_t[:, action] / b_prob
        r = sensors.cumulants(self.stream.readings[t + 1], self.sensor, self.threshold)
        return Step(action, b_prob, self.stream.features[t + 1], r, np.zeros_like(r), self.gamma, rho, pi_tp1)


def _block(size: int, learner: str, policy: str = "given", classes: np.ndarray | None = None) -> Block:
    k = sensors.ACTIVE
    return Block(
        learner,
        np.full(size, ALPHA / k),
        np.full(size, ALPHA_W / k),
        LAMBDA,
        policy,  # type: ignore[arg-type]
        classes,
    )


def _split(total: int, parts: int) -> list[int]:
    """`total` demons into `parts` groups as even as they go (no empty group)."""
    parts = min(parts, total)
    return [total // parts + (1 if p < total % parts else 0) for p in range(parts)]


def make(
    name: str,
    demons: int,
    steps: int,
    learner: str | None = None,
    dtype: str = "float64",
    cut: float = TRACE_CUT,
    seed: int = 0,
) -> ScaleWorkload:
    """A workload of `demons` demons over `steps` transitions."""
    rng = np.random.default_rng(seed)
    stream = sensors.make_stream(steps + 1, seed)
    scales = sensors.TIMESCALES
    if name in ("nexting", "control"):
        sizes = _split(demons, len(scales))
        if name == "nexting":
            blocks = [_block(n, learner or "td") for n in sizes]
            gamma = scales[: len(sizes)]
        else:
            blocks = [_block(n, "gq", "softmax") for n in sizes]
            gamma = np.repeat(scales[: len(sizes)], sizes)
    elif name == "off_policy":
        per_policy = np.array(_split(demons, POLICIES))  # [P] questions of each policy
        timescale = np.arange(len(per_policy)) % len(scales)  # [P]
        blocks, gamma = [], []
        for t in range(min(len(scales), len(per_policy))):
            counts = per_policy[timescale == t]
            blocks.append(
                _block(int(counts.sum()), learner or "gtd", classes=np.repeat(np.arange(len(counts)), counts))
            )
            gamma.extend([scales[t]] * len(counts))
    else:
        raise ValueError(f"unknown workload {name!r}")
    layout = Layout(tuple(blocks), sensors.NUM_FEATURES, sensors.ACTIVE, np.dtype(dtype), cut)
    sensor, threshold = np.concatenate(
        [np.stack(sensors.threshold_cumulants(b.size, seed + 1 + i)) for i, b in enumerate(blocks)], axis=1
    )
    actions = rng.integers(0, A, steps) if name != "nexting" else np.zeros(steps, dtype=np.int64)
    extra = {}
    if name == "off_policy":
        nc = layout.num_classes
        extra = {
            "policy_sensor": rng.integers(0, sensors.SENSORS, nc),
            "policy_bias": rng.normal(0.0, 1.0, (nc, A)),
            "policy_gain": rng.normal(0.0, 2.0, (nc, A)),
        }
    return ScaleWorkload(
        name, layout, stream, sensor.astype(np.int64), threshold, np.asarray(gamma, dtype=float), actions, **extra
    )
