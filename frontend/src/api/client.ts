/**
 * The typed REST client (openapi-fetch over the generated `paths`) and the one way its answers are
 * unwrapped: data on success, an `ApiError` otherwise.
 */
import createClient, { type Middleware } from "openapi-fetch";
import type { paths } from "./schema";
import type { ValidationProblem } from "./types";
import { readToken } from "./token";

/** A refused request: `problems` holds a 422's located problems, `message` the rest. */
export class ApiError extends Error {
  constructor(
    readonly status: number,
    message: string,
    readonly problems: ValidationProblem[] = [],
  ) {
    super(message);
    this.name = "ApiError";
  }
}

/**
 * Adds `Authorization: Bearer <token>` to every request when a token is set: the changes need it, and
 * GET /api/me and /api/tokens answer by it (the other reads ignore it).
 */
const auth: Middleware = {
  onRequest({ request }) {
    const token = readToken();
    if (token) request.headers.set("Authorization", `Bearer ${token}`);
    return request;
  },
};

// The global fetch is looked up at each request, not when the client is made (tests stub it).
export const api = createClient<paths>({ baseUrl: "", fetch: (request) => globalThis.fetch(request) });
api.use(auth);

interface Answer<T> {
  data?: T;
  error?: unknown;
  response: Response;
}

/** The data of a successful answer; throws `ApiError` for any other status. */
export async function unwrap<T>(pending: Promise<Answer<T>>): Promise<T> {
  const { data, error, response } = await pending;
  if (response.ok) return data as T;
  throw toApiError(response.status, error);
}

/** FastAPI's error bodies: `{detail: string}`, or `{detail: [{loc, msg, type}]}` for a 422. */
export function toApiError(status: number, body: unknown): ApiError {
  const detail = typeof body === "object" && body !== null ? (body as { detail?: unknown }).detail : undefined;
  if (Array.isArray(detail)) {
    const problems = detail as ValidationProblem[];
    return new ApiError(status, problems.map((p) => p.msg).join("; "), problems);
  }
  if (typeof detail === "string") return new ApiError(status, detail);
  return new ApiError(status, `the server answered ${status}`);
}

/** A message for the user, whatever was thrown. */
export function errorMessage(error: unknown): string {
  if (error instanceof ApiError) return error.message;
  if (error instanceof Error) return error.message;
  return String(error);
}
