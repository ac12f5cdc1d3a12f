/**
 * The WebSocket stream of one run (WS /api/runs/{id}/stream): messages shaped like GET
 * /api/runs/{id}/state (`StateOut`), at most about 30 a second. A dropped connection is retried;
 * the server's "unknown run" and "run deleted" closes end the stream for good.
 */
import type { RunState } from "./types";

const CLOSE_UNKNOWN_RUN = 4404;
const CLOSE_RUN_DELETED = 4410;
const RETRY_MS = 1000;

export function streamUrl(runId: string, location: Pick<Location, "protocol" | "host">): string {
  const scheme = location.protocol === "https:" ? "wss" : "ws";
  return `${scheme}://${location.host}/api/runs/${encodeURIComponent(runId)}/stream`;
}

export class RunStream {
  private socket: WebSocket | null = null;
  private retry: number | undefined;
  private closed = false;

  constructor(
    private readonly runId: string,
    private readonly onState: (state: RunState) => void,
    private readonly onEnd: (reason: string) => void = () => {},
  ) {
    this.connect();
  }

  close(): void {
    this.closed = true;
    window.clearTimeout(this.retry);
    const socket = this.socket;
    this.socket = null;
    if (!socket) return;
    // Closing a socket that is still connecting makes Chromium log an error; close it once open.
    if (socket.readyState === WebSocket.CONNECTING) socket.onopen = () => socket.close(1000);
    else if (socket.readyState === WebSocket.OPEN) socket.close(1000);
  }

  private connect(): void {
    const socket = new WebSocket(streamUrl(this.runId, window.location));
    this.socket = socket;
    socket.onmessage = (event) => {
      if (this.socket === socket) this.onState(JSON.parse(String(event.data)) as RunState);
    };
    socket.onclose = (event) => {
      if (this.closed || this.socket !== socket) return;
      if (event.code === CLOSE_UNKNOWN_RUN || event.code === CLOSE_RUN_DELETED) {
        this.onEnd(event.reason || "the run is gone");
        return;
      }
      this.retry = window.setTimeout(() => this.connect(), RETRY_MS);
    };
  }
}
