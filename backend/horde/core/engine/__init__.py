"""The one engine: blocks of demons with feature-major weights and shared sparse traces, stepped by a compiled loop.

* `blocks`: what a block is (one learner, one lambda, one kind of target policy) and its trace classes;
* `layout`: the compiled layout and state as small NamedTuples of arrays with named fields;
* `rows`, `traces`, `values`: the row primitives, the one trace kernel (merge, decay, cut) and the values,
  policies and predictions read at a state, shared by every learner (`horde.core.learners`);
* `grid`, `metrics`, `step`, `loop`: the grid world compiled, RUPEE and UDE, one learning step for every
  demon (and the one helper that splits a block's columns over threads), and the loop over steps;
* `pack`, `engine`: the Python side: packing a compiled `Horde` into the layout, and `Engine`, the state in
  and out.
"""
