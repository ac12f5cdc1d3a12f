"""One colour per demon, the same in the dashboard (its table and charts) and in the live view's charts.

A demon's colour is chosen by its place in the run's demon list; the dashboard reads it from
`GET /api/runs/{id}/demons` (`colour`), so the palette is written here only. Okabe and Ito's eight colours,
told apart under the common colour-vision deficiencies and on a projector; yellow is left out (it vanishes
on white), dark blue-grey takes its place.
"""

from __future__ import annotations

DEMON_COLOURS = ("#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#5C6B7A")


def demon_colour(index: int) -> str:
    """The colour of the demon at `index` (0-based) in its run's demon list."""
    return DEMON_COLOURS[index % len(DEMON_COLOURS)]
