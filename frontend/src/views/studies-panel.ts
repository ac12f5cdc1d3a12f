/**
 * The Studies tab: define a parameter study (a scenario, axes with their values, runs per configuration),
 * launch it on the server (POST /api/studies, run on Ray as `horde study` runs it), watch its progress,
 * then read (1) learning curves per configuration with 95 % bootstrap bands over runs, (2) sensitivity
 * curves of the final or mean error against any swept axis, one curve per value of another, and (3) a
 * sortable table of configurations with the best marked; export the results as CSV or JSON. Below, runs
 * and protocol jobs side by side (`compare-panel.ts`).
 */
import "./studies.css";
import type { AppStore } from "../app/state";
import { ApiError, api, errorMessage, unwrap } from "../api/client";
import { formatNumber } from "../lib/format";
import {
  type AxisValue,
  type SortKey,
  type Study,
  type StudyConfig,
  type StudyDetail,
  type StudyIn,
  bestConfigs,
  configLabel,
  defaultAxes,
  isNumericAxis,
  parseValues,
  sensitivityCurves,
  shortPath,
  sortConfigs,
  studyProgress,
  varyingAxes,
} from "../lib/study";
import { h, options, replaceChildren, setText } from "../ui/dom";
import { FormErrors, field, numberInput, textInput } from "../ui/form";
import { comparePanel } from "./compare-panel";
import { bandChart } from "./study-chart";

const DEFAULT_SCENARIO = "classroom-offpolicy";
const SUGGESTED_PATHS = [
  "learning.alpha",
  "learning.alpha_w",
  "learning.lambda",
  "demons.*.learner",
  "demons.*.alpha",
  "demons.*.lambda",
  "features.tiles",
  "world.slip",
  "seed",
];
const CURVES_SHOWN = 6;
const POLL_MS = 1000;
const ERROR_HELP =
  "Error: root-mean-square error of each demon's prediction over every state against the exact answer " +
  "(Monte-Carlo truth at the start where no exact answer exists), divided by the size of that answer, " +
  "averaged over the demons. Bands and intervals: 95 % bootstrap over the runs. AUC: the mean error over " +
  "the learning curve (after episode 0), small when learning is fast.";

interface AxisRow {
  path: HTMLInputElement;
  values: HTMLInputElement;
  row: HTMLElement;
}

export function studiesPanel(store: AppStore): HTMLElement {
  const errors = new FormErrors();
  const scenario = h("select", { name: "scenario" });
  const runs = numberInput(3, { name: "runs", min: 1 });
  const episodes = numberInput(300, { name: "episodes", min: 1 });
  const checkpoints = numberInput(10, { name: "checkpoints", min: 1 });
  const submit = h("button", { type: "submit", class: "primary" }, "Launch");
  const datalist = h(
    "datalist",
    { id: "study-paths" },
    SUGGESTED_PATHS.map((p) => h("option", { value: p })),
  );
  const axesBox = h("div", { class: "study-axes" });
  const axisRows: AxisRow[] = [];

  const addAxis = (path = "", values = "") => {
    const i = axisRows.length;
    const pathInput = textInput(path, { name: `axis-path-${i}`, list: "study-paths", placeholder: "learning.alpha" });
    const valuesInput = textInput(values, { name: `axis-values-${i}`, placeholder: "0.01, 0.03, 0.1" });
    const remove = h("button", { type: "button", class: "ghost", "aria-label": `Remove axis ${i + 1}` }, "Remove");
    const row = h(
      "div",
      { class: "row study-axis" },
      field(`Axis ${i + 1}: field path`, pathInput, { path: `axes.${i}.path`, errors, class: "wide" }),
      field("Values (comma-separated)", valuesInput, { path: `axes.${i}.values`, errors, class: "wide" }),
      remove,
    );
    const entry = { path: pathInput, values: valuesInput, row };
    remove.addEventListener("click", () => {
      axisRows.splice(axisRows.indexOf(entry), 1);
      row.remove();
    });
    axisRows.push(entry);
    axesBox.append(row);
  };
  addAxis("learning.alpha", "0.03, 0.1, 0.3");
  addAxis("demons.*.learner", "td, gq");
  const addButton = h("button", { type: "button", onclick: () => addAxis() }, "Add an axis");

  const renderChoices = () => {
    const names = store.state.scenarios.filter((x) => !x.error).map((x) => x.name);
    const chosen = scenario.dataset.chosen ? scenario.value : DEFAULT_SCENARIO;
    replaceChildren(scenario, options(names, chosen));
  };
  scenario.addEventListener("change", () => (scenario.dataset.chosen = "yes"));

  // ---------------------------------------------------------------- studies and the selected one

  let studies: Study[] = [];
  let selectedId: string | null = null;
  let detail: StudyDetail | null = null;
  let sortKey: SortKey = "error";
  let ascending = true;
  let shown = new Set<number>(); // configuration indices on the learning-curve chart
  let userChose = false; // until the user ticks or unticks one, the chart shows the best configurations
  let shownFor: string | null = null;

  const onSubmit = async (event: Event) => {
    event.preventDefault();
    errors.clear();
    // fields left out take the server's defaults (the generated type lists defaults as required)
    const body = {
      scenario: scenario.value,
      runs: Number(runs.value),
      measure: { episodes: Number(episodes.value), checkpoints: Number(checkpoints.value) },
      axes: axisRows.map((a) => ({ path: a.path.value.trim(), values: parseValues(a.values.value) })),
    } as StudyIn;
    submit.disabled = true;
    try {
      const started = await unwrap(api.POST("/api/studies", { body }));
      selectedId = started.id;
      detail = null;
      await refresh();
    } catch (error) {
      if (error instanceof ApiError && error.problems.length > 0) errors.showProblems(error.problems);
      else errors.showGeneral(errorMessage(error));
    } finally {
      submit.disabled = false;
    }
  };

  const list = h("select", { name: "study", "aria-label": "Study" });
  list.addEventListener("change", () => {
    selectedId = list.value || null;
    detail = null;
    void refresh();
  });

  const title = h("h3", { id: "study-title" });
  const badge = h("span", { class: "badge" });
  const progress = h("progress", { class: "study-progress", "aria-labelledby": "study-title" });
  const counted = h("span", { dataset: { testid: "study-count" } });
  const left = h("span", { class: "progress-timing" });
  const message = h("p", { class: "hint" });
  const cancel = h("button", { type: "button", class: "danger" }, "Cancel");
  const resume = h("button", { type: "button" }, "Resume");
  const exportCsv = h("a", { class: "button", download: "" }, "Export CSV");
  const exportJson = h("a", { class: "button", download: "" }, "Export JSON");
  const curves = h("div", { class: "study-curves" });
  const sensitivity = h("div", { class: "study-sensitivity" });
  const xAxis = h("select", { name: "sensitivity-x", "aria-label": "Sensitivity: along" });
  const groupAxis = h("select", { name: "sensitivity-group", "aria-label": "Sensitivity: one curve per" });
  const metric = h(
    "select",
    { name: "sensitivity-metric", "aria-label": "Sensitivity: measure" },
    options([
      ["final", "final error"],
      ["auc", "mean error over training (AUC)"],
    ] as const),
  );
  let axesChosen = false;
  for (const select of [xAxis, groupAxis, metric])
    select.addEventListener("change", () => {
      axesChosen = true;
      drawSensitivity();
    });
  const table = h("div", { class: "study-table" });

  cancel.addEventListener("click", () => {
    if (!selectedId) return;
    cancel.disabled = true;
    void act(() =>
      unwrap(api.DELETE("/api/studies/{study_id}", { params: { path: { study_id: selectedId as string } } })),
    );
  });
  resume.addEventListener("click", () => {
    if (!selectedId) return;
    void act(() =>
      unwrap(api.POST("/api/studies/{study_id}/resume", { params: { path: { study_id: selectedId as string } } })),
    );
  });

  const act = async (request: () => Promise<unknown>) => {
    try {
      await request();
    } catch (error) {
      setText(message, errorMessage(error));
    }
    await refresh();
  };

  const job = h(
    "section",
    { class: "study-job", "aria-labelledby": "study-title", hidden: true },
    h(
      "div",
      { class: "panel-head" },
      h("div", { class: "job-title" }, title, badge),
      h("div", { class: "row" }, cancel, resume, exportCsv, exportJson),
    ),
    progress,
    h("p", { class: "progress-text" }, counted, left),
    message,
    h("h4", {}, "Learning curves"),
    h(
      "p",
      { class: "hint" },
      "Mean over runs with its 95 % bootstrap band; tick configurations in the table to draw them.",
    ),
    curves,
    h("h4", {}, "Sensitivity"),
    h("div", { class: "row" }, field("Along", xAxis), field("One curve per", groupAxis), field("Measure", metric)),
    sensitivity,
    h("h4", {}, "Configurations"),
    h("p", { class: "hint" }, ERROR_HELP),
    table,
  );

  const refresh = async () => {
    try {
      studies = await unwrap(api.GET("/api/studies"));
    } catch {
      return; // the next poll tries again
    }
    if (selectedId === null && studies.length > 0) selectedId = (studies[studies.length - 1] as Study).id;
    replaceChildren(
      list,
      studies
        .slice()
        .reverse()
        .map((x) =>
          h(
            "option",
            { value: x.id, selected: x.id === selectedId },
            `${x.name ?? x.id} · ${x.status} · ${x.tasks_done}/${x.tasks}`,
          ),
        ),
    );
    const brief = studies.find((x) => x.id === selectedId);
    if (!brief) {
      job.hidden = true;
      return;
    }
    const stale =
      !detail || detail.id !== brief.id || detail.tasks_done !== brief.tasks_done || detail.status !== brief.status;
    if (stale) {
      try {
        detail = await unwrap(api.GET("/api/studies/{study_id}", { params: { path: { study_id: brief.id } } }));
      } catch (error) {
        setText(message, errorMessage(error));
        return;
      }
      renderDetail();
    }
  };

  const renderDetail = () => {
    if (!detail) return;
    job.hidden = false;
    const running = detail.status === "running" || detail.status === "created";
    setText(
      title,
      `${detail.name ?? detail.id}: ${detail.configurations} configurations x ${detail.runs} runs, ${detail.episodes} episodes each`,
    );
    setText(badge, detail.status);
    badge.className = `badge status-${detail.status}`;
    const shownProgress = studyProgress(detail);
    progress.max = Math.max(1, detail.tasks);
    progress.value = detail.tasks_done;
    progress.setAttribute("aria-valuetext", shownProgress.counted);
    setText(counted, shownProgress.counted);
    setText(left, shownProgress.left ? ` · ${shownProgress.left}` : "");
    setText(message, detail.message);
    cancel.hidden = !running;
    cancel.disabled = false;
    resume.hidden = running || detail.status === "finished";
    exportCsv.href = `/api/studies/${detail.id}/export?format=csv`;
    exportJson.href = `/api/studies/${detail.id}/export?format=json`;
    const results = detail.results;
    if (shownFor !== detail.id) {
      shownFor = detail.id;
      userChose = false;
      axesChosen = false;
    }
    if (!axesChosen) {
      // until the user picks, the defaults follow the results as they come in
      const { x, group } = defaultAxes(results);
      fillAxisChoices(results, x, group);
    }
    if (!userChose) shown = new Set(bestConfigs(results, CURVES_SHOWN).map((c) => c.index));
    drawCurves();
    drawSensitivity();
    drawTable();
  };

  const fillAxisChoices = (results: StudyConfig[], x: string | null, group: string | null) => {
    const paths = results.length > 0 ? Object.keys((results[0] as StudyConfig).axes) : [];
    replaceChildren(xAxis, options(paths, x ?? undefined));
    replaceChildren(groupAxis, options([["", "(none)"], ...paths.map((p) => [p, p] as const)], group ?? ""));
  };

  const drawCurves = () => {
    if (!detail) return;
    const chosen = detail.results.filter((c) => shown.has(c.index));
    if (chosen.length === 0) {
      replaceChildren(curves, h("p", { class: "hint" }, "No finished run yet."));
      return;
    }
    replaceChildren(
      curves,
      bandChart(
        chosen.map((c) => ({
          label: `${configLabel(c.axes)} (${c.runs} runs)`,
          x: c.episodes,
          ...c.curve,
          best: c.best,
        })),
        {
          title: "Relative error while learning",
          xLabel: "training episodes",
          yLabel: "relative error",
          logY: true,
          style: "band",
        },
      ),
    );
  };

  const drawSensitivity = () => {
    if (!detail) return;
    const results = detail.results;
    const x = xAxis.value;
    if (!x || varyingAxes(results).length === 0) {
      replaceChildren(
        sensitivity,
        h("p", { class: "hint" }, "Sensitivity curves need an axis with two values or more."),
      );
      return;
    }
    const group = groupAxis.value || null;
    const which = metric.value === "auc" ? "auc" : "final";
    const numeric = isNumericAxis(results, x);
    const categories = numeric ? undefined : [...new Set(results.map((c) => String(c.axes[x])))].sort();
    const position = (v: AxisValue) => (numeric ? (v as number) : (categories as string[]).indexOf(String(v)));
    const lines = sensitivityCurves(results, x, group, which);
    const values = results.map((c) => c.axes[x]).filter((v): v is number => typeof v === "number");
    const logX = numeric && values.every((v) => v > 0) && Math.max(...values) / Math.min(...values) >= 10;
    const others = Object.keys(results[0]?.axes ?? {}).filter((p) => p !== x && p !== group);
    replaceChildren(
      sensitivity,
      bandChart(
        lines.map((line) => ({
          label: group ? `${shortPath(group)}=${String(line.group)}` : "all",
          x: line.points.map((p) => position(p.x)),
          mean: line.points.map((p) => p.mean),
          low: line.points.map((p) => p.low),
          high: line.points.map((p) => p.high),
        })),
        {
          title:
            `${which === "final" ? "Final error" : "Mean error over training"} against ${x}` +
            (others.length ? ` (best over ${others.join(", ")})` : ""),
          xLabel: x,
          yLabel: which === "final" ? "final relative error" : "AUC",
          logX,
          logY: true,
          style: "bars",
          categories,
        },
      ),
    );
  };

  const drawTable = () => {
    if (!detail) return;
    const results = detail.results;
    const paths = results.length > 0 ? Object.keys((results[0] as StudyConfig).axes) : [];
    const header = (label: string, key: SortKey) =>
      h(
        "th",
        { scope: "col", "aria-sort": sortKey === key ? (ascending ? "ascending" : "descending") : "none" },
        h(
          "button",
          {
            type: "button",
            class: "sort",
            onclick: () => {
              ascending = sortKey === key ? !ascending : true;
              sortKey = key;
              drawTable();
            },
          },
          label,
          sortKey === key ? (ascending ? " ▲" : " ▼") : "",
        ),
      );
    const rows = sortConfigs(results, sortKey, ascending).map((c) => {
      const tick = h("input", {
        type: "checkbox",
        checked: shown.has(c.index),
        "aria-label": `Draw ${configLabel(c.axes)}`,
      });
      tick.addEventListener("change", () => {
        userChose = true;
        if (tick.checked) shown.add(c.index);
        else shown.delete(c.index);
        drawCurves();
      });
      return h(
        "tr",
        { class: c.best ? "best" : "", dataset: { config: String(c.index) } },
        h("td", {}, tick),
        h("td", {}, c.best ? h("strong", { title: "the lowest final error" }, "★ best") : ""),
        paths.map((p) => h("td", { class: "num" }, String(c.axes[p]))),
        h("td", { class: "num" }, String(c.runs)),
        h("td", { class: "num" }, formatNumber(c.error, 4)),
        h("td", { class: "num" }, `${formatNumber(c.ci_low, 4)} – ${formatNumber(c.ci_high, 4)}`),
        h("td", { class: "num" }, formatNumber(c.auc, 4)),
      );
    });
    replaceChildren(
      table,
      h(
        "table",
        { class: "data-table study-configs" },
        h(
          "thead",
          {},
          h(
            "tr",
            {},
            h("th", { scope: "col" }, "draw"),
            h("th", { scope: "col" }, ""),
            paths.map((p) => header(p, `axis:${p}`)),
            h("th", { scope: "col" }, "runs"),
            header("error", "error"),
            h("th", { scope: "col" }, "95 % CI"),
            header("AUC", "auc"),
          ),
        ),
        h("tbody", {}, rows),
      ),
    );
  };

  // Poll while the tab is shown (studies started elsewhere, the CLI included, appear too).
  let timer: number | null = null;
  const watch = () => {
    const visible = store.state.tab === "studies";
    if (visible && timer === null) {
      void refresh();
      timer = window.setInterval(() => void refresh(), POLL_MS);
    } else if (!visible && timer !== null) {
      window.clearInterval(timer);
      timer = null;
    }
  };
  store.subscribe(watch, ["tab"]);
  store.subscribe(renderChoices, ["scenarios"]);
  renderChoices();
  watch();

  return h(
    "section",
    { class: "panel studies-panel", "aria-labelledby": "studies-title" },
    h("h2", { id: "studies-title" }, "Studies"),
    h(
      "p",
      { class: "hint intro" },
      "How do learners and their parameters compare? A study varies fields of a scenario (each axis: a field path " +
        "and its values), gives every configuration independent runs, and measures each demon's error against the " +
        "exact answer as it learns. It runs on the server's Ray, as ",
      h("code", {}, "horde study"),
      " does.",
    ),
    h(
      "form",
      { class: "study-form", novalidate: true, onsubmit: onSubmit, "aria-labelledby": "studies-title" },
      h(
        "div",
        { class: "row" },
        field("Scenario", scenario, { path: "scenario", errors, class: "wide" }),
        field("Runs per configuration", runs, { path: "runs", errors }),
        field("Episodes per run", episodes, { path: "measure.episodes", errors }),
        field("Checkpoints", checkpoints, { path: "measure.checkpoints", errors }),
      ),
      datalist,
      axesBox,
      h("div", { class: "row" }, addButton, h("div", { class: "submit-cell" }, submit)),
      errors.general,
    ),
    h("div", { class: "row" }, field("Study", list)),
    job,
    comparePanel(store),
  );
}
