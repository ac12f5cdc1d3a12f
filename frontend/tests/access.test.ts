// @vitest-environment happy-dom
import { afterEach, describe, expect, it } from "vitest";
import { mayChange, roleStyles } from "../src/app/access";
import type { Me } from "../src/api/types";
import { sparkPaths } from "../src/views/class-tab";
import type { RunCard } from "../src/api/types";

const me = (role: Me["role"], name: string | null = role): Me => ({ role, name, id: name, tokens: true });

/** Which of the page's marked controls the role's style sheet leaves visible. */
function visible(who: Me | null): string[] {
  document.body.innerHTML = `
    <button id="launch" class="needs-change"></button>
    <button id="issue" class="needs-teacher"></button>
    <li data-owner="alice"><button id="alices-pause" class="needs-owner"></button></li>
    <li data-owner="teacher"><button id="teachers-pause" class="needs-owner"></button></li>
    <button id="select"></button>`;
  const sheet = document.createElement("style");
  sheet.textContent = roleStyles(who);
  document.head.append(sheet);
  const shown = [...document.querySelectorAll("button")].filter((b) => getComputedStyle(b).display !== "none");
  sheet.remove();
  return shown.map((b) => b.id);
}

describe("the controls each role is shown", () => {
  afterEach(() => (document.body.innerHTML = ""));

  it("the teacher sees every control", () => {
    expect(visible(me("teacher"))).toEqual(["launch", "issue", "alices-pause", "teachers-pause", "select"]);
  });

  it("a student sees the changes and their own things' controls, not the teacher's", () => {
    expect(visible(me("student", "alice"))).toEqual(["launch", "alices-pause", "select"]);
    expect(visible(me("student", "bob"))).toEqual(["launch", "select"]);
  });

  it("a viewer and an anonymous page see no control that changes anything", () => {
    expect(visible(me("viewer", "vic"))).toEqual(["select"]);
    expect(visible(me("anonymous", null))).toEqual(["select"]);
  });

  it("a name that is no CSS identifier still matches only its owner", () => {
    document.body.innerHTML = "";
    expect(roleStyles(me("student", 'al"ice]'))).toContain('[data-owner="al\\"ice\\]"]');
  });

  it("mayChange follows the server's rule", () => {
    expect(mayChange(me("teacher"), "alice")).toBe(true);
    expect(mayChange(me("student", "alice"), "alice")).toBe(true);
    expect(mayChange(me("student", "alice"), "teacher")).toBe(false);
    expect(mayChange(me("viewer", "vic"), "vic")).toBe(false);
    expect(mayChange(null, "teacher")).toBe(false);
  });
});

describe("sparkPaths", () => {
  const card = (series: Record<string, (number | null)[]>, steps = [0, 10, 20]): RunCard => ({
    id: "r",
    name: "r",
    owner: "teacher",
    status: "running",
    episode: 0,
    step: 20,
    updated_at: "",
    sparkline: { steps, series },
  });

  it("scales each series on its own range across the box, left to right", () => {
    const [small, large] = sparkPaths(card({ small: [0, 0.5, 1], large: [100, 0, 50] }), 100, 42);
    expect(small).toBe("0.0,41.0 50.0,21.0 100.0,1.0");
    expect(large).toBe("0.0,1.0 50.0,41.0 100.0,21.0");
  });

  it("leaves out nulls, draws a flat series across the middle, and nothing from one point", () => {
    expect(sparkPaths(card({ d: [1, null, 1] }), 100, 40)).toEqual(["0.0,20.0 100.0,20.0"]);
    expect(sparkPaths(card({ d: [null, null, null] }))).toEqual([""]);
    expect(sparkPaths(card({ d: [3] }, [5]))).toEqual([""]);
  });
});
