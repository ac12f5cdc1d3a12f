/**
 * The Studies tab: define a parameter study (a scenario, axes with their values, runs per configuration),
 * launch it on the server (POST /api/studies, run on Ray as `horde study` runs it), watch its progress,
 * then read (1) learning curves per configuration with 95 % bootstrap bands over runs, (2) sensitivity
 * curves of the final or mean error against any swept axis, one curve per value of another, and (3) a
 * sortable table of configurations with the best marked; export the results as CSV or JSON. Below, runs
 * and protocol jobs side by side (`compare-panel.ts`).
 */
import "./studies.css";
import { html } from "lit-html";
import type { App } from "../app/app";
import { keys, readNow, watchQuery } from "../app/queries";
import { reads } from "../app/reads";
import { mount } from "../app/view";
import { api, errorMessage, unwrap } from "../api/client";
import { formatCountOf } from "../lib/format";
import { type Study, type StudyDetail, studyProgress, studySize } from "../lib/study";
import { selectField } from "../ui/form";
import { heading, host } from "../ui/html";
import type { Scope } from "../ui/scope";
import { comparePanel } from "./compare-panel";
import { studyForm } from "./study-form";
import { StudyResults } from "./study-results";

const POLL_MS = 1000;

/** The study shown, and what the page says about it. */
interface Shown {
  app: App;
  id: string | null;
  message: string | null;
  /** a Cancel or Resume under way */
  busy: boolean;
  results: StudyResults;
  refresh: () => Promise<void>;
  draw: () => void;
}

export function studiesPanel(app: App, scope: Scope): HTMLElement {
  const element = host(html`<section class="panel studies-panel" aria-labelledby="studies-title"></section>`);
  const redraw = () => draw();
  const shown: Shown = {
    app,
    id: null,
    message: null,
    busy: false,
    results: new StudyResults(redraw),
    refresh: async () => {},
    draw: redraw,
  };
  const form = studyForm(app, scope, async (id) => {
    shown.id = id;
    await shown.refresh();
  });
  const compare = comparePanel(app, scope);
  const draw = mount(app, scope, element, ["tab"], () => {
    const studies = app.client.getQueryData<Study[]>(keys.studies) ?? [];
    const detail = shown.id === null ? undefined : app.client.getQueryData<StudyDetail>(keys.study(shown.id));
    return html`${heading({ id: "studies-title", title: "Studies" })}
      <p class="hint intro">
        How do learners and their parameters compare? A study varies fields of a scenario (each axis: a field path and
        its values), gives every configuration independent runs, and measures each demon's error against the exact
        answer as it learns. It runs on the server's Ray, as <code>horde study</code> does.
      </p>
      ${form}
      <div class="row">${studyChoice(shown, studies)}</div>
      ${jobSection(shown, detail)} ${compare}`;
  });
  watchStudies(shown, scope);
  return element;
}

/**
 * The study list is a query read every second while the tab is shown (studies started elsewhere, the CLI
 * included, appear too); the study shown is read again when its progress moves.
 */
function watchStudies(shown: Shown, scope: Scope): void {
  const { app } = shown;
  const watchOf = () => ({ ...reads.studies(), every: POLL_MS, enabled: app.ui.state.tab === "studies" });
  const onList = async (studies: Study[]) => {
    if (shown.id === null && studies.length > 0) shown.id = (studies.at(-1) as Study).id;
    shown.draw();
    const brief = studies.find((s) => s.id === shown.id);
    const detail = shown.id === null ? undefined : app.client.getQueryData<StudyDetail>(keys.study(shown.id));
    const stale = !detail || detail.tasks_done !== brief?.tasks_done || detail.status !== brief?.status;
    if (brief && stale) await readStudy(shown, brief.id);
  };
  const list = watchQuery(app.client, watchOf(), (read) => void onList(read), undefined, scope);
  scope.add(app.ui.subscribe(() => list.update(watchOf()), ["tab"]));
  shown.refresh = () => list.refetch();
}

async function readStudy(shown: Shown, id: string): Promise<void> {
  try {
    await readNow(shown.app.client, reads.study(id));
    shown.message = null;
  } catch (error) {
    shown.message = errorMessage(error);
  }
  shown.draw();
}

function studyChoice(shown: Shown, studies: Study[]) {
  const choose = (event: Event) => {
    shown.id = (event.target as HTMLSelectElement).value || null;
    // drawn at once: until the chosen study is read, the last one's progress and results must not stand under it
    shown.draw();
    void shown.refresh();
  };
  return selectField(
    { label: "Study", id: "study-choice" },
    { name: "study", onChange: choose },
    studies
      .slice()
      .reverse()
      .map(
        (x) =>
          html`<option value=${x.id} .selected=${x.id === shown.id}>
            ${x.name ?? x.id} · ${x.status} · ${x.tasks_done}/${x.tasks}
          </option>`,
      ),
  );
}

/** The study shown: its progress, Cancel or Resume, its exports and its results. */
function jobSection(shown: Shown, detail: StudyDetail | undefined) {
  if (!detail) return html`<section class="study-job" aria-labelledby="study-title" hidden></section>`;
  const running = detail.status === "running" || detail.status === "created";
  const progress = studyProgress(detail);
  const act = (request: () => Promise<unknown>) => async () => {
    shown.busy = true;
    shown.draw();
    try {
      await request();
    } catch (error) {
      shown.message = errorMessage(error);
    }
    shown.busy = false;
    await shown.refresh();
    shown.draw();
  };
  const path = { params: { path: { study_id: detail.id } } };
  return html`<section class="study-job" aria-labelledby="study-title">
    <div class="panel-head">
      <div class="job-title">
        <h3 id="study-title">
          ${detail.name ?? detail.id}: ${studySize(detail)}, ${formatCountOf(detail.episodes, "episode")} each
        </h3>
        <span class="badge status-${detail.status}">${detail.status}</span>
      </div>
      <div class="row">
        <button
          type="button"
          class="danger needs-teacher"
          ?hidden=${!running}
          @click=${act(() => unwrap(api.DELETE("/api/studies/{study_id}", path)))}
        >
          Cancel
        </button>
        <button
          type="button"
          class="needs-teacher"
          ?hidden=${running || detail.status === "finished"}
          @click=${act(() => unwrap(api.POST("/api/studies/{study_id}/resume", path)))}
        >
          Resume
        </button>
        <a class="button" download href="/api/studies/${detail.id}/export?format=csv">Export CSV</a>
        <a class="button" download href="/api/studies/${detail.id}/export?format=curves">Export curves CSV</a>
        <a class="button" download href="/api/studies/${detail.id}/export?format=json">Export JSON</a>
      </div>
    </div>
    <progress
      class="study-progress"
      aria-labelledby="study-title"
      max=${Math.max(1, detail.tasks)}
      .value=${detail.tasks_done}
      aria-valuetext=${progress.counted}
    ></progress>
    <p class="progress-text">
      <span data-testid="study-count">${progress.counted}</span
      ><span class="progress-timing">${progress.left ? ` · ${progress.left}` : ""}</span>
    </p>
    <p class="hint">${shown.message ?? detail.message}</p>
    ${shown.results.template(detail)}
  </section>`;
}
