"""The run layer: live runs with their learner threads, protocol jobs, snapshots, history and the SQLite store.

Arrows point one way: `server`, `view` and `cli` use this package; it uses `core` and `spec`.
"""
