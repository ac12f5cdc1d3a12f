/**
 * The WebSocket stream of one run (WS /api/runs/{id}/stream): messages shaped like GET
 * /api/runs/{id}/state (`RunStreamMessage`, a `StateOut`), at most about 30 a second. A dropped
 * connection is retried; the server's "unknown run" and "run deleted" closes end the stream for good.
 * The message type and the close codes are generated from the server's (stream_protocol.py).
 */
import { StreamClose } from "./stream-protocol";
import type { RunStreamMessage } from "./types";

const RETRY_MS = 1000;
/** The closes after which connecting again cannot help. */
const FINAL_CLOSES: ReadonlySet<number> = new Set([StreamClose.NOT_FOUND, StreamClose.RUN_DELETED]);

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
    private readonly onState: (state: RunStreamMessage) => void,
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
    if (socket.readyState === WebSocket.CONNECTING) socket.onopen = () => socket.close(StreamClose.NORMAL);
    else if (socket.readyState === WebSocket.OPEN) socket.close(StreamClose.NORMAL);
  }

  private connect(): void {
    const socket = new WebSocket(streamUrl(this.runId, window.location));
    this.socket = socket;
    socket.onmessage = (event) => {
      if (this.socket === socket) this.onState(JSON.parse(String(event.data)) as RunStreamMessage);
    };
    socket.onclose = (event) => {
      if (this.closed || this.socket !== socket) return;
      if (FINAL_CLOSES.has(event.code)) {
        this.onEnd(event.reason || "the run is gone");
        return;
      }
      this.retry = window.setTimeout(() => this.connect(), RETRY_MS);
    };
  }
}
