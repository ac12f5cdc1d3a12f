/**
 * Where the tour's dialog goes beside the part of the page it explains, and where the page scrolls to first:
 * the part in sight from its top (where the live view draws its value map's legend), the dialog never over
 * the part's upper half. Pure numbers in, numbers out (the tour measures the page and applies the answer).
 *
 * In order of preference: the dialog just below the part, or just above it, the window scrolled (within
 * what the page allows) to make room; else beside it; else, for a part too tall to share the window with
 * the dialog, over the part's lowest visible part, the part shown from its top.
 */

export const GAP = 8; // px between the dialog, its part and the window's edges

export interface Box {
  /** document coordinates: top and height along the page, left and right across it */
  top: number;
  height: number;
  left: number;
  right: number;
}

export interface Space {
  width: number; // the window's
  height: number;
  /** the scroll positions the page allows now: [0, scrollHeight - innerHeight], or one position to stay */
  minScroll: number;
  maxScroll: number;
}

export interface Placement {
  scroll: number; // the window's scroll position (top)
  left: number; // the dialog's, in window coordinates
  top: number;
}

const clamp = (value: number, low: number, high: number) => Math.max(low, Math.min(high, value));

/** Where to scroll and put a `dialog` (width, height) for `part` in `space`. */
export function tourPlacement(part: Box, dialog: { width: number; height: number }, space: Space): Placement {
  const at = (scroll: number) => clamp(scroll, space.minScroll, Math.max(space.minScroll, space.maxScroll));
  const left = clamp(part.left + 2 * GAP, GAP, space.width - dialog.width - GAP);
  const fits = (top: number) => top >= GAP && top + dialog.height <= space.height - GAP;

  // Below the part, the part's top at the window's top (or as near as the page allows).
  let scroll = at(part.top - GAP);
  let top = part.top - scroll + part.height + GAP;
  if (fits(top)) return { scroll, left, top };
  // Above the part, the dialog at the window's top.
  scroll = at(part.top - dialog.height - 2 * GAP);
  top = part.top - scroll - GAP - dialog.height;
  if (fits(top)) return { scroll, left, top };

  // Beside it, the part from its top (centred if it is short).
  const spare = space.height - part.height;
  scroll = at(part.top - (spare > 2 * GAP ? spare / 2 : GAP));
  const partTop = part.top - scroll;
  const beside =
    part.left - dialog.width - GAP >= GAP
      ? part.left - dialog.width - GAP
      : part.right + GAP + dialog.width <= space.width - GAP
        ? part.right + GAP
        : null;
  if (beside !== null) return { scroll, left: beside, top: clamp(partTop, GAP, space.height - dialog.height - GAP) };

  // Over its lowest part in sight, the part from its top.
  scroll = at(part.top - GAP);
  const bottom = Math.min(part.top - scroll + part.height, space.height);
  return { scroll, left, top: Math.max(GAP, bottom - dialog.height - GAP) };
}
