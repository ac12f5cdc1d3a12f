// @vitest-environment happy-dom
import { render } from "lit-html";
import { afterEach, beforeEach, describe, expect, it, vi } from "vitest";
import { CONFIRM_MS, Confirm, confirmButton } from "../src/ui/confirm";
import { Scope } from "../src/ui/scope";

/** A confirm button drawn into a box, drawn again whenever it arms or turns back (as a view does). */
function make(onConfirm = vi.fn(), disabled = () => false) {
  const box = document.createElement("div");
  const scope = new Scope();
  const onChange = vi.fn(() => draw());
  const confirm = new Confirm(scope, onChange);
  const draw = () =>
    render(
      confirmButton(confirm, {
        text: (armed) => (armed ? "Really delete?" : "Delete"),
        label: (armed) => (armed ? "Really delete run a?" : "Delete run a"),
        onConfirm,
        disabled: disabled(),
      }),
      box,
    );
  draw();
  const button = box.querySelector("button") as HTMLButtonElement;
  const text = () => button.textContent?.trim();
  return { confirm, button, text, onConfirm, onChange, scope, draw };
}

describe("confirmButton", () => {
  beforeEach(() => vi.useFakeTimers());
  afterEach(() => vi.useRealTimers());

  it("acts on the second press only, and says so in its words and its name", () => {
    const { confirm, button, text, onConfirm, onChange } = make();
    expect(text()).toBe("Delete");
    expect(button.getAttribute("aria-label")).toBe("Delete run a");
    button.click();
    expect(onConfirm).not.toHaveBeenCalled();
    expect(confirm.armed).toBe(true);
    expect(text()).toBe("Really delete?");
    expect(button.getAttribute("aria-label")).toBe("Really delete run a?");
    expect(onChange).toHaveBeenCalledTimes(1);
    button.click();
    expect(onConfirm).toHaveBeenCalledTimes(1);
    expect(confirm.armed).toBe(false);
    expect(text()).toBe("Delete");
    // A third press starts over: it arms again, it does not act.
    button.click();
    expect(onConfirm).toHaveBeenCalledTimes(1);
  });

  it("turns back by itself after the wait, so a late second press only arms again", () => {
    const { confirm, button, text, onConfirm } = make();
    button.click();
    vi.advanceTimersByTime(CONFIRM_MS - 1);
    expect(confirm.armed).toBe(true);
    vi.advanceTimersByTime(1);
    expect(confirm.armed).toBe(false);
    expect(text()).toBe("Delete");
    button.click();
    expect(onConfirm).not.toHaveBeenCalled();
    expect(confirm.armed).toBe(true);
  });

  it("is not fooled by a disabled button or an owner that disarms it", () => {
    let disabled = false;
    const { confirm, button, text, onConfirm, draw } = make(vi.fn(), () => disabled);
    button.click();
    confirm.disarm();
    expect(text()).toBe("Delete");
    button.click();
    disabled = true;
    draw();
    button.dispatchEvent(new Event("click"));
    expect(onConfirm).not.toHaveBeenCalled();
    // Arming again restarts the wait: the first arming's timer does not cut the second short.
    disabled = false;
    draw();
    confirm.disarm();
    vi.advanceTimersByTime(CONFIRM_MS - 100);
    button.click();
    vi.advanceTimersByTime(200);
    expect(confirm.armed).toBe(true);
  });

  it("leaves no timer behind when its view goes", () => {
    const { button, scope } = make();
    button.click();
    expect(vi.getTimerCount()).toBe(1);
    scope.dispose();
    expect(vi.getTimerCount()).toBe(0);
  });
});
