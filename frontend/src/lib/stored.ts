/**
 * Switches this browser remembers (large text, classroom mode, the tour taken), in localStorage; where
 * storage is disabled they work for the page and are forgotten with it.
 */

export function readFlag(key: string): boolean {
  try {
    return localStorage.getItem(key) === "1";
  } catch {
    return false;
  }
}

export function writeFlag(key: string, on: boolean): void {
  try {
    localStorage.setItem(key, on ? "1" : "");
  } catch {
    // storage disabled: the switch still works for this page
  }
}
