/**
 * This page's own key for the live view. The page embeds the view at the address GET /api/view gives
 * for this key (its WebSocket address carries it) and tells the server its selected run with the same
 * key (POST /api/view): only this page's view (and a standalone tab opened from its link) follows it,
 * never another page's. A fresh key per page load: a duplicated tab must not share its original's view.
 */
function randomKey(): string {
  const bytes = crypto.getRandomValues(new Uint8Array(16)); // crypto.randomUUID needs a secure context
  return Array.from(bytes, (b) => b.toString(16).padStart(2, "0")).join("");
}

export const VIEWER_KEY = randomKey();
