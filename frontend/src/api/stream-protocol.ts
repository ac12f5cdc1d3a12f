/**
 * The WebSocket streams' close codes, generated from the server's OpenAPI schema (`StreamClose`, built
 * from backend/horde/server/stream_protocol.py) by `npm run gen:api`. Do not edit.
 */
import type { components } from "./schema";

export const StreamClose = {
  /** the stream is over (a study stopped) */
  NORMAL: 1000,
  /** the server is stopping */
  GOING_AWAY: 1001,
  /** a page of another site may not open the stream */
  ORIGIN_REFUSED: 1008,
  /** the client fell too far behind, or a send timed out ('try again later') */
  TOO_SLOW: 1013,
  /** the server requires a token (pushing records to a stream run), or the token given is not the server's or was revoked */
  UNAUTHORIZED: 4401,
  /** the token's role may not do this (a viewer's, or a student's on another's stream run) */
  FORBIDDEN: 4403,
  /** no such run (or study, or stream run) */
  NOT_FOUND: 4404,
  /** the run (or stream run) was deleted while streamed */
  RUN_DELETED: 4410,
} as const satisfies Record<string, components["schemas"]["StreamClose"]>;

export type StreamCloseCode = (typeof StreamClose)[keyof typeof StreamClose];
