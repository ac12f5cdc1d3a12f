/**
 * Compare and export: tick two or more runs to see their demons and prediction curves side by side, or
 * protocol jobs to see their results side by side; every run and job has its export links (history or
 * results as CSV and JSON, a run's spec as TOML, so a user can share exactly what ran).
 */
import { type App, state, watchState } from "../app/app";
import type { Scope } from "../ui/scope";
import { api, errorMessage, unwrap } from "../api/client";
import type { History, Protocol, RunBrief, RunState } from "../api/types";
import { formatNumber, runLabel } from "../lib/format";
import { h, replaceChildren } from "../ui/dom";
import { bandChart } from "./study-chart";

const MAX_POINTS = 300;

function link(href: string, text: string): HTMLAnchorElement {
  return h("a", { href, download: "", class: "button small" }, text);
}

export function runExports(runId: string): HTMLElement {
  return h(
    "span",
    { class: "exports" },
    link(`/api/runs/${runId}/export/history?format=csv`, "History CSV"),
    link(`/api/runs/${runId}/export/history?format=json`, "History JSON"),
    link(`/api/runs/${runId}/export/spec`, "Spec TOML"),
  );
}

export function comparePanel(app: App, scope: Scope): HTMLElement {
  const chosenRuns = new Set<string>();
  const chosenJobs = new Set<string>();
  const runList = h("ul", { class: "compare-list" });
  const jobList = h("ul", { class: "compare-list" });
  const side = h("div", { class: "compare-side" });
  const compare = h("button", { type: "button", class: "primary" }, "Compare");
  const note = h("p", { class: "hint", "aria-live": "polite" });
  let jobs: Protocol[] = [];

  const renderRuns = () => {
    replaceChildren(
      runList,
      state(app).runs.map((run: RunBrief) => {
        const tick = h("input", {
          type: "checkbox",
          checked: chosenRuns.has(run.id),
          "aria-label": `Compare ${runLabel(run)}`,
        });
        tick.addEventListener("change", () => (tick.checked ? chosenRuns.add(run.id) : chosenRuns.delete(run.id)));
        return h(
          "li",
          { dataset: { run: run.id } },
          h("label", {}, tick, ` ${runLabel(run)} · ${run.status}`),
          runExports(run.id),
        );
      }),
    );
  };

  const loadJobs = async () => {
    try {
      jobs = await unwrap(api.GET("/api/protocols"));
    } catch {
      jobs = [];
    }
    replaceChildren(
      jobList,
      jobs.map((job) => {
        const tick = h("input", {
          type: "checkbox",
          checked: chosenJobs.has(job.id),
          "aria-label": `Compare protocol ${job.id}`,
        });
        tick.addEventListener("change", () => (tick.checked ? chosenJobs.add(job.id) : chosenJobs.delete(job.id)));
        const ready = job.results !== null && job.results !== undefined;
        return h(
          "li",
          {},
          h("label", {}, tick, ` ${job.name ?? job.id} · ${job.status} · ${job.trials} x ${job.episodes} episodes`),
          ready
            ? h(
                "span",
                { class: "exports" },
                link(`/api/protocols/${job.id}/export?format=csv`, "Results CSV"),
                link(`/api/protocols/${job.id}/export?format=json`, "Results JSON"),
              )
            : "",
        );
      }),
    );
  };

  const runColumn = async (runId: string): Promise<HTMLElement> => {
    const path = { run_id: runId };
    const [run, state] = await Promise.all([
      unwrap(api.GET("/api/runs/{run_id}", { params: { path } })),
      unwrap(api.GET("/api/runs/{run_id}/state", { params: { path } })) as Promise<RunState>,
    ]);
    const names = Object.keys(state.predictions);
    const histories: History[] = await Promise.all(
      names.map((name) =>
        unwrap(
          api.GET("/api/runs/{run_id}/demons/{name}/history", {
            params: { path: { run_id: runId, name }, query: { limit: 2000 } },
          }),
        ),
      ),
    );
    const series = histories.map((hist) => {
      const stride = Math.max(1, Math.ceil(hist.step.length / MAX_POINTS));
      const keep = hist.step.map((_, i) => i).filter((i) => i % stride === 0);
      const mean = keep.map((i) => hist.prediction[i] ?? null);
      return {
        label: hist.demon,
        x: keep.map((i) => hist.step[i] as number),
        mean,
        low: mean.map(() => null),
        high: mean.map(() => null),
      };
    });
    return h(
      "div",
      { class: "compare-column", dataset: { run: runId } },
      h("h4", {}, `${runLabel(run)} · ${run.status} · step ${state.step}`),
      h(
        "table",
        { class: "data-table" },
        h(
          "thead",
          {},
          h(
            "tr",
            {},
            h("th", { scope: "col" }, "demon"),
            h("th", { scope: "col", class: "num" }, "prediction now"),
            h("th", { scope: "col", class: "num" }, "RUPEE"),
          ),
        ),
        h(
          "tbody",
          {},
          names.map((name) =>
            h(
              "tr",
              {},
              h("td", {}, name),
              h("td", { class: "num" }, formatNumber(state.predictions[name])),
              h("td", { class: "num" }, formatNumber(state.metrics?.[name]?.rupee)),
            ),
          ),
        ),
      ),
      bandChart(series, { title: "Predictions over time", xLabel: "step", yLabel: "prediction", style: "band" }),
      runExports(runId),
    );
  };

  const jobColumn = (job: Protocol): HTMLElement =>
    h(
      "div",
      { class: "compare-column" },
      h("h4", {}, `protocol ${job.name ?? job.id} · seed ${job.seed} · ${job.trials} x ${job.episodes}`),
      h(
        "table",
        { class: "data-table" },
        h(
          "thead",
          {},
          h(
            "tr",
            {},
            ["demon", "prediction", "truth", "error", "thesis"].map((t, i) =>
              h("th", { scope: "col", class: i ? "num" : "" }, t),
            ),
          ),
        ),
        h(
          "tbody",
          {},
          (job.results ?? []).map((r) =>
            h(
              "tr",
              {},
              h("td", {}, r.name),
              h("td", { class: "num" }, formatNumber(r.prediction)),
              h("td", { class: "num" }, formatNumber(r.truth)),
              h("td", { class: "num" }, formatNumber(r.error)),
              h("td", { class: "num" }, formatNumber(r.thesis)),
            ),
          ),
        ),
      ),
    );

  compare.addEventListener("click", async () => {
    const total = chosenRuns.size + chosenJobs.size;
    if (total < 2) {
      note.textContent = "Tick two or more runs or protocol jobs.";
      return;
    }
    note.textContent = "";
    try {
      const columns = await Promise.all([...chosenRuns].map(runColumn));
      const jobColumns = jobs.filter((j) => chosenJobs.has(j.id)).map(jobColumn);
      replaceChildren(side, columns, jobColumns);
    } catch (error) {
      note.textContent = errorMessage(error);
    }
  });

  watchState(app, scope, ["runs"], renderRuns);
  renderRuns();
  const refreshJobs = h("button", { type: "button", onclick: () => void loadJobs() }, "Refresh the protocol jobs");
  void loadJobs();

  return h(
    "section",
    { class: "compare-panel", "aria-labelledby": "compare-title" },
    h("h3", { id: "compare-title" }, "Compare and export"),
    h("p", { class: "hint" }, "Tick two or more runs or protocol jobs and press Compare to see them side by side."),
    h("h4", {}, "Runs"),
    runList,
    h("h4", {}, "Protocol jobs"),
    jobList,
    h("div", { class: "row" }, refreshJobs, compare),
    note,
    side,
  );
}
