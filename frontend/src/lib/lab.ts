/** The Lab tab's pure parts: a refused set-up's problems by the set-up field they name. */
import { ApiError, errorMessage } from "../api/client";

/** A 422's problems by set-up field (`["body", "setup", name]`), the rest under ""; any other error under "". */
export function setupProblems(error: unknown): Record<string, string> {
  if (!(error instanceof ApiError) || error.problems.length === 0) return { "": errorMessage(error) };
  const out: Record<string, string> = {};
  for (const problem of error.problems) {
    const at = problem.loc[1] === "setup" && problem.loc.length > 2 ? String(problem.loc[2]) : "";
    out[at] = out[at] ? `${out[at]}; ${problem.msg}` : problem.msg;
  }
  return out;
}
