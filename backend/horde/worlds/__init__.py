"""World kinds beyond the grid: Gymnasium environments, live streams and recorded logs.

The grid world lives in `horde.core.world` and is simulated inside the compiled loop; these worlds are
stepped (or read) in Python and feed the engine one transition at a time through `horde.core.learner.Learner`.
"""
