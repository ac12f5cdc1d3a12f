// @vitest-environment happy-dom
import { afterEach, beforeEach, describe, expect, it, vi } from "vitest";
import { CONFIRM_MS, confirmButton } from "../src/ui/legacy-confirm";

function make(onConfirm = vi.fn(), onChange = vi.fn()) {
  const confirm = confirmButton({
    text: (armed) => (armed ? "Really delete?" : "Delete"),
    label: (armed) => (armed ? "Really delete run a?" : "Delete run a"),
    onConfirm,
    onChange,
  });
  return { confirm, onConfirm, onChange };
}

describe("confirmButton", () => {
  beforeEach(() => vi.useFakeTimers());
  afterEach(() => vi.useRealTimers());

  it("acts on the second press only, and says so in its words and its name", () => {
    const { confirm, onConfirm, onChange } = make();
    expect(confirm.button.textContent).toBe("Delete");
    expect(confirm.button.getAttribute("aria-label")).toBe("Delete run a");
    confirm.button.click();
    expect(onConfirm).not.toHaveBeenCalled();
    expect(confirm.armed()).toBe(true);
    expect(confirm.button.textContent).toBe("Really delete?");
    expect(confirm.button.getAttribute("aria-label")).toBe("Really delete run a?");
    expect(onChange).toHaveBeenCalledTimes(1);
    confirm.button.click();
    expect(onConfirm).toHaveBeenCalledTimes(1);
    expect(confirm.armed()).toBe(false);
    expect(confirm.button.textContent).toBe("Delete");
    // A third press starts over: it arms again, it does not act.
    confirm.button.click();
    expect(onConfirm).toHaveBeenCalledTimes(1);
  });

  it("turns back by itself after the wait, so a late second press only arms again", () => {
    const { confirm, onConfirm } = make();
    confirm.button.click();
    vi.advanceTimersByTime(CONFIRM_MS - 1);
    expect(confirm.armed()).toBe(true);
    vi.advanceTimersByTime(1);
    expect(confirm.armed()).toBe(false);
    expect(confirm.button.textContent).toBe("Delete");
    confirm.button.click();
    expect(onConfirm).not.toHaveBeenCalled();
    expect(confirm.armed()).toBe(true);
  });

  it("is not fooled by a disabled button or an owner that disarms it", () => {
    const { confirm, onConfirm } = make();
    confirm.button.click();
    confirm.disarm();
    expect(confirm.button.textContent).toBe("Delete");
    confirm.button.click();
    confirm.button.disabled = true;
    confirm.button.dispatchEvent(new Event("click"));
    expect(onConfirm).not.toHaveBeenCalled();
    // Arming again restarts the wait: the first arming's timer does not cut the second short.
    confirm.button.disabled = false;
    confirm.disarm();
    vi.advanceTimersByTime(CONFIRM_MS - 100);
    confirm.button.click();
    vi.advanceTimersByTime(200);
    expect(confirm.armed()).toBe(true);
  });
});
