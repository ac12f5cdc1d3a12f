// @vitest-environment happy-dom
import { describe, expect, it } from "vitest";
import type { Run } from "../src/api/types";
import { createApp } from "../src/app/app";
import { keys } from "../src/app/queries";
import type { LearnerInfo } from "../src/lib/learners";
import { Scope } from "../src/ui/scope";
import { demonEditor } from "../src/views/demon-editor";

const learner = (name: string, traces: boolean): LearnerInfo => ({
  name,
  text: `${name}'s line`,
  paper: "",
  action_values: name === "gq",
  secondary: true,
  traces,
  step_sizes: ["constant"],
  parameters: [],
});

const run = {
  id: "abc123",
  name: "chain",
  status: "paused",
  spec: { world: {}, learning: { lambda: 0.8, alpha: 0.1, alpha_w: 0.01 } },
} as unknown as Run;

describe("demonEditor", () => {
  it("shows λ as 0, not editable, with why, for a learner without traces (gtd1), and takes it again for td", () => {
    const app = createApp();
    app.client.setQueryData(keys.learners, [learner("gq", true), learner("td", true), learner("gtd1", false)]);
    app.client.setQueryData(keys.run(run.id), run);
    app.client.setQueryData(keys.demons(run.id), []);
    app.ui.update({ selectedRunId: run.id });
    const form = demonEditor(app, new Scope());
    document.body.append(form);
    const lambda = () => form.querySelector<HTMLInputElement>('input[name="lambda"]') as HTMLInputElement;
    const choose = (name: string) => {
      const select = form.querySelector<HTMLSelectElement>('select[name="learner"]') as HTMLSelectElement;
      select.value = name;
      select.dispatchEvent(new Event("change", { bubbles: true }));
    };
    expect(lambda().disabled).toBe(false);
    choose("gtd1");
    expect(lambda().disabled).toBe(true);
    expect(lambda().value).toBe("0");
    const hint = form.querySelector(`#${lambda().getAttribute("aria-describedby")?.split(" ")[0] ?? "none"}`);
    expect(hint?.textContent).toContain("gtd1 learns with λ 0 only");
    choose("td");
    expect(lambda().disabled).toBe(false);
    expect(form.textContent).not.toContain("learns with λ 0 only");
    form.remove();
  });
});
