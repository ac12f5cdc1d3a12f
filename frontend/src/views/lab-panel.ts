/**
 * The Lab tab: Sutton and Barto's prediction experiments and the gradient-TD chains as a list a class runs
 * (GET /api/lab). Each says what the class should see; its set-up (alpha, lambda, basis order; a figure's
 * runs) can be changed before running it again. A run launches live and the Live tab shows it (the viser view
 * draws the chain with every state's value beside the truth); a figure runs as a study on the server and is
 * drawn here under its caption as its runs finish: learning curves with their 95 % bootstrap bands,
 * sensitivity curves and the table (the Studies tab's results). A set-up the server refuses shows its 422 at
 * the field it names.
 */
import { html } from "lit-html";
import { attempt, launchRun } from "../app/actions";
import type { App } from "../app/app";
import { keys, readNow } from "../app/queries";
import { reads } from "../app/reads";
import { mount } from "../app/view";
import { api, errorMessage, unwrap } from "../api/client";
import type { LabExperiment, RunTemplate, StudyDetail, StudyIn } from "../api/types";
import { setupProblems } from "../lib/lab";
import { studyProgress, studySize } from "../lib/study";
import { heading, host } from "../ui/html";
import type { Scope } from "../ui/scope";
import { StudyResults } from "./study-results";

const POLL_MS = 1000;

interface Figure {
  experiment: string;
  study: string;
  caption: string;
}

/** The tab's own state. */
interface Lab {
  app: App;
  experiments: LabExperiment[];
  /** per experiment, per set-up field: the text typed */
  typed: Record<string, Record<string, string>>;
  /** per experiment, per set-up field ("" for the experiment as a whole): the server's objection */
  problems: Record<string, Record<string, string>>;
  busy: string | null;
  figure: Figure | null;
  results: StudyResults;
  draw: () => void;
}

export function labPanel(app: App, scope: Scope): HTMLElement {
  const element = host(html`<section class="panel lab-panel" aria-labelledby="lab-title"></section>`);
  const lab: Lab = {
    app,
    experiments: [],
    typed: {},
    problems: {},
    busy: null,
    figure: null,
    results: new StudyResults(() => lab.draw()),
    draw: () => {},
  };
  lab.draw = mount(app, scope, element, ["tab"], () => template(lab));
  void attempt(app, async () => {
    const experiments = await unwrap(api.GET("/api/lab"));
    lab.experiments = Array.isArray(experiments) ? experiments : []; // a server without the lab lists none
    lab.draw();
  });
  const timer = window.setInterval(() => {
    const detail = figureDetail(lab);
    const running = lab.figure && (!detail || detail.status === "created" || detail.status === "running");
    if (running && app.ui.state.tab === "lab" && !document.hidden) void readFigure(lab);
  }, POLL_MS);
  scope.add(() => window.clearInterval(timer));
  return element;
}

function figureDetail(lab: Lab): StudyDetail | undefined {
  return lab.figure ? lab.app.client.getQueryData<StudyDetail>(keys.study(lab.figure.study)) : undefined;
}

function template(lab: Lab) {
  return html`${heading({ id: "lab-title", title: "Lab" })}
    <p class="hint intro">
      Sutton and Barto's prediction experiments and the gradient-TD papers' chains. A run learns live: the Live tab
      shows its demons, and the view draws the chain with every state's value beside the truth. A figure runs as a study
      on the server and is drawn below as its runs finish, with 95 % bootstrap bands. Change the set-up and run it
      again.
    </p>
    <ul class="lab-list">
      ${lab.experiments.map((experiment) => item(lab, experiment))}
    </ul>
    ${lab.figure ? figureSection(lab, lab.figure, figureDetail(lab)) : ""}`;
}

function item(lab: Lab, experiment: LabExperiment) {
  lab.typed[experiment.id] ??= {};
  const typed = lab.typed[experiment.id] as Record<string, string>;
  const problems = lab.problems[experiment.id] ?? {};
  const field = (name: string, shipped: string) => {
    const id = `lab-${experiment.id}-${name}`;
    const problem = problems[name];
    return html`<span class="lab-field">
      <label for=${id}>${name}</label>
      <input
        id=${id}
        name=${name}
        .value=${typed[name] ?? shipped}
        aria-invalid=${problem ? "true" : "false"}
        aria-describedby=${`${id}-problem`}
        @input=${(event: Event) => {
          typed[name] = (event.target as HTMLInputElement).value;
        }}
      />
      <span class="field-error" id=${`${id}-problem`} ?hidden=${!problem}>${problem ?? ""}</span>
    </span>`;
  };
  return html`<li class="lab-item" data-testid=${`lab-${experiment.id}`}>
    <h3>${experiment.title}</h3>
    <p class="lab-see">${experiment.see}</p>
    <div class="row lab-setup">
      ${experiment.setup.map((s) => field(s.name, s.value))}
      <button type="button" ?disabled=${lab.busy !== null} @click=${() => void start(lab, experiment)}>
        ${experiment.kind === "run" ? "Run live" : "Run the figure"}
      </button>
    </div>
    <p class="field-error" ?hidden=${!problems[""]}>${problems[""] ?? ""}</p>
  </li>`;
}

async function start(lab: Lab, experiment: LabExperiment): Promise<void> {
  lab.busy = experiment.id;
  lab.problems[experiment.id] = {};
  lab.draw();
  try {
    const prepared = await unwrap(
      api.POST("/api/lab/{experiment_id}/prepare", {
        params: { path: { experiment_id: experiment.id } },
        body: { setup: lab.typed[experiment.id] ?? {} },
      }),
    );
    if (prepared.kind === "run") {
      await launchRun(lab.app, prepared.spec as unknown as RunTemplate, undefined, true);
      lab.app.ui.update({ tab: "live" });
    } else {
      const study = await unwrap(api.POST("/api/studies", { body: prepared.spec as unknown as StudyIn }));
      const caption = typeof prepared.spec.caption === "string" ? prepared.spec.caption : "";
      lab.figure = { experiment: experiment.id, study: study.id, caption };
      await readFigure(lab);
    }
  } catch (error) {
    lab.problems[experiment.id] = setupProblems(error);
  }
  lab.busy = null;
  lab.draw();
}

async function readFigure(lab: Lab): Promise<void> {
  const figure = lab.figure;
  if (!figure) return;
  try {
    await readNow(lab.app.client, reads.study(figure.study));
  } catch (error) {
    lab.problems[figure.experiment] = { "": errorMessage(error) };
  }
  lab.draw();
}

function figureSection(lab: Lab, figure: Figure, detail: StudyDetail | undefined) {
  const progress = detail ? studyProgress(detail) : null;
  return html`<section class="lab-figure" aria-labelledby="lab-figure-title">
    <div class="panel-head">
      <h3 id="lab-figure-title">${detail?.name ?? figure.experiment}</h3>
      <span class="badge status-${detail?.status ?? "created"}" data-testid="lab-status"
        >${detail?.status ?? "starting"}</span
      >
    </div>
    <p class="lab-caption">${figure.caption}</p>
    <p class="hint" ?hidden=${!detail}>
      This run: ${detail ? studySize(detail) : ""} (the caption says the figure's set-up as shipped).
    </p>
    <progress max=${Math.max(1, detail?.tasks ?? 1)} .value=${detail?.tasks_done ?? 0}></progress>
    <p class="progress-text">${progress?.counted ?? ""}</p>
    ${detail && detail.results.length > 0 ? lab.results.template(detail) : ""}
  </section>`;
}
