/**
 * The HORDE_TOKEN the user typed in, kept for this browser tab only (sessionStorage), so that a
 * server started with a token can be driven from the dashboard without the token outliving the tab.
 */
const KEY = "horde-lab-token";

export function readToken(): string {
  try {
    return sessionStorage.getItem(KEY) ?? "";
  } catch {
    return ""; // storage can be disabled; the dashboard then works without a token
  }
}

export function writeToken(token: string): void {
  try {
    if (token) sessionStorage.setItem(KEY, token);
    else sessionStorage.removeItem(KEY);
  } catch {
    // see readToken
  }
}
