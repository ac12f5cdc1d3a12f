"""The one loop: many steps of one agent in one compiled call, each a transition from its source and the learning
step of every demon (`step.learn`).

The source is the grid world (`Given` empty: the behaviour acts, the world moves, new episodes start as they
end) or the rows of `Given` (a world fed from outside: row t's sensors, action and b(a_t | s_t); the caller
starts episodes), learned at position (0, 0). The call releases the GIL: the server's other threads go on
while a run learns.
"""

from __future__ import annotations

from numba import njit

from horde.core.engine import grid
from horde.core.engine.layout import NO_NRT
from horde.core.engine.step import apply_rules, behaviour, learn, observe, settle

# Result fields of `run` (Agent.result).
R_STEPS, R_EPISODES, R_ACTION, R_REWARD, R_TERMINATED, R_TRUNCATED, R_SIGN, R_BPROB = range(8)


@njit(**NO_NRT, nogil=True)
def run(t, rng, max_steps, max_episodes, beh, with_metrics, threads, given):
    """Run steps until `max_steps` steps or `max_episodes` episode ends (see the module); the last step's
    result in t.agent.result (R_*). Every owed correction is paid before it returns (`step.settle`)."""
    agent, world = t.agent, t.world
    from_world = given.sensors.shape[0] == 0
    sensors, result, returns = agent.sensors, agent.result, agent.returns
    steps = 0
    episodes = 0
    while steps < max_steps and episodes < max_episodes:
        if not from_world:  # the next given transition
            for j in range(sensors.shape[0]):
                sensors[j] = given.sensors[steps, j]
            apply_rules(given.rules, sensors, t.cls.fixed)
            action, b_prob, terminated = given.actions[steps], given.b_probs[steps], given.terminated[steps]
            learn(t, action, b_prob, terminated, 0.0, 0.0, threads, with_metrics)
            if given.pred_out.shape[0] > 0:
                for j in range(t.dem.pred.shape[0]):
                    given.pred_out[steps, j] = t.dem.pred[j]
            steps += 1
            continue
        behaviour(beh, t.dem.q, agent.probs)  # the behaviour acts, the world moves
        total = 0.0
        for a in range(agent.probs.shape[0]):
            total += agent.probs[a]
            agent.cdf[a] = total
        action = grid.draw(rng, agent.cdf, agent.probs.shape[0])
        reward, terminated, terminal = grid.move(rng, world, agent, action)
        truncated = agent.steps[0] >= world.max_steps and not terminated
        b_prob = agent.probs[action]
        learn(t, action, b_prob, terminated, agent.pos[0], agent.pos[1], threads, with_metrics)
        steps += 1
        returns[0] += reward
        result[R_ACTION] = action
        result[R_REWARD] = reward
        result[R_TERMINATED] = 1.0 if terminated else 0.0
        result[R_TRUNCATED] = 1.0 if truncated else 0.0
        result[R_SIGN] = 1.0 if terminal > 0 else (-1.0 if terminal < 0 else 0.0)
        result[R_BPROB] = b_prob
        if terminated or truncated:  # (the next episode's `observe` pays what is owed)
            episodes += 1
            returns[1] = returns[0]
            returns[0] = 0.0
            start(t, rng)
    settle(t)  # whoever reads theta after the loop sees it whole
    result[R_STEPS] = steps
    result[R_EPISODES] = episodes


@njit(**NO_NRT)
def start(t, rng):
    """A new episode on the grid world: the world draws its start and colours, the Horde observes the first
    state."""
    grid.reset(rng, t.world, t.agent)
    grid.start_sensors(t.world, t.agent)
    observe(t, t.agent.pos[0], t.agent.pos[1], t.agent.start_sensors)
