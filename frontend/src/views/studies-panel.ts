/**
 * The Studies tab: define a parameter study (a scenario, axes with their values, runs per configuration),
 * launch it on the server (POST /api/studies, run on Ray as `horde study` runs it), watch its progress,
 * then read (1) learning curves per configuration with 95 % bootstrap bands over runs, (2) sensitivity
 * curves of the final or mean error against any swept axis, one curve per value of another, and (3) a
 * sortable table of configurations with the best marked; export the results as CSV or JSON. Below, runs
 * and protocol jobs side by side (`compare-panel.ts`).
 */
import "./studies.css";
import { keys, queryClient, watchQuery } from "../app/queries";
import type { AppStore } from "../app/state";
import { api, errorMessage, unwrap } from "../api/client";
import { type Study, type StudyDetail, studyProgress } from "../lib/study";
import { h, replaceChildren, section, setText } from "../ui/dom";
import { field } from "../ui/form";
import { comparePanel } from "./compare-panel";
import { studyForm } from "./study-form";
import { studyResults } from "./study-results";

const POLL_MS = 1000;

export function studiesPanel(store: AppStore): HTMLElement {
  let studies: Study[] = [];
  let selectedId: string | null = null;
  let detail: StudyDetail | null = null;
  const results = studyResults();

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
  const exportCurves = h("a", { class: "button", download: "" }, "Export curves CSV");
  const exportJson = h("a", { class: "button", download: "" }, "Export JSON");
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
      h("div", { class: "row" }, cancel, resume, exportCsv, exportCurves, exportJson),
    ),
    progress,
    h("p", { class: "progress-text" }, counted, left),
    message,
    results.element,
  );

  // The study list is a query read every second while the tab is shown (studies started elsewhere, the
  // CLI included, appear too); a failed reading is tried again at the next.
  const watchOf = () => ({
    queryKey: keys.studies,
    queryFn: () => unwrap(api.GET("/api/studies")),
    every: POLL_MS,
    enabled: store.state.tab === "studies",
  });
  const studyList = watchQuery(queryClient, watchOf(), (read) => void show(read));
  store.subscribe(() => studyList.update(watchOf()), ["tab"]);
  const refresh = () => studyList.refetch();

  const show = async (read: Study[]) => {
    studies = read;
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
    exportCurves.href = `/api/studies/${detail.id}/export?format=curves`;
    exportJson.href = `/api/studies/${detail.id}/export?format=json`;
    results.show(detail);
  };

  return section(
    { class: "panel studies-panel", id: "studies-title", title: "Studies" },
    h(
      "p",
      { class: "hint intro" },
      "How do learners and their parameters compare? A study varies fields of a scenario (each axis: a field path " +
        "and its values), gives every configuration independent runs, and measures each demon's error against the " +
        "exact answer as it learns. It runs on the server's Ray, as ",
      h("code", {}, "horde study"),
      " does.",
    ),
    studyForm(store, async (id) => {
      selectedId = id;
      detail = null;
      await refresh();
    }),
    h("div", { class: "row" }, field("Study", list)),
    job,
    comparePanel(store),
  );
}
