/**
 * Short names for the generated API types (schema.d.ts). Aliases only: every shape is defined once,
 * by the server's pydantic models; `npm run gen:api` regenerates the schema when they change.
 */
import type { components } from "./schema";

type Schemas = components["schemas"];

export type RunBrief = Schemas["RunBriefOut"];
export type Run = Schemas["RunOut"];
export type RunStatus = RunBrief["status"];
export type RunSpec = Schemas["RunSpec-Output"];
export type RunTemplate = Schemas["RunTemplateIn"];
export type RunState = Schemas["StateOut"];
/** A message of a run's WebSocket stream (a `RunState`, `type: "state"`). */
export type RunStreamMessage = Schemas["RunStreamMessage"];
export type DemonMetrics = Schemas["DemonMetricsOut"];
export type Demon = Schemas["DemonOut"];
export type DemonSpec = Schemas["DemonSpec-Input"];
export type PolicySpec = Schemas["PolicySpec"];
export type FeatureSpec = Schemas["FeatureSpec"];
export type Expr = DemonSpec["cumulant"];
export type WorldSpec = Schemas["WorldSpec"];
/** Any kind of world a run spec holds: the grid world (which has no `kind`), a Gymnasium environment, a stream. */
export type AnyWorldSpec = NonNullable<Schemas["RunSpec-Input"]["world"]> | NonNullable<RunSpec["world"]>;

/** The grid world of a run spec, or undefined for the other kinds (they have no plane, start or regions). */
export function gridWorld(world: AnyWorldSpec | null | undefined): WorldSpec | undefined {
  return world && !("kind" in world) ? world : undefined;
}
export type WorldRecord = Schemas["WorldOut"];
export type Region = Schemas["Region"];
export type RegionKind = Region["kind"];
export type Color = Schemas["Color"];
export type Scenario = Schemas["ScenarioOut"];
export type Evaluation = Schemas["EvaluationOut"];
/** What Evaluate offers on a run's world: from a point (grid), from the current state (rollouts), or none. */
export type EvaluationKind = Schemas["EvaluationSupportOut"]["kind"];

/** A run's evaluation kind; a server that does not say is taken to offer today's grid evaluation. */
export function evaluationKind(run: { evaluation?: { kind: EvaluationKind } } | null): EvaluationKind {
  return run?.evaluation?.kind ?? "grid";
}
export type History = Schemas["HistoryOut"];
export type Summary = Schemas["SummaryOut"];
export type ValidationProblem = Schemas["ValidationError"];
export type Protocol = Schemas["ProtocolOut"];
export type ProtocolStatus = Protocol["status"];
export type DemonResult = Schemas["DemonResultOut"];
export type Counts = Schemas["CountsOut"];
export type LiveViewInfo = Schemas["ViewOut"];
export type Study = Schemas["StudyOut"];
export type StudyDetail = Schemas["StudyResultsOut"];
export type StudyConfig = Schemas["StudyConfigOut"];
export type StudyIn = Schemas["StudySpec"];
export type Band = Schemas["BandOut"];
/** A stream run (a world of kind `stream`): its counters and every demon's latest prediction. */
export type StreamRun = Schemas["StreamOut"];
/** The strip chart's data: recent sensors, predictions made at the time, realised returns computed afterwards. */
export type StreamHistory = Schemas["StreamHistoryOut"];
/** Who the dashboard acts as (GET /api/me): its token's role, or anonymous (no token on a server with roles). */
export type Me = Schemas["MeOut"];
export type Role = Me["role"];
/** A student's or viewer's token, as the teacher's Class panel lists it (never its secret). */
export type Token = Schemas["TokenOut"];
/** A token just issued: its secret and an invitation link carrying it, shown once. */
export type TokenIssued = Schemas["TokenIssuedOut"];
/** A run as the Class tab's card shows it (GET /api/overview). */
export type RunCard = Schemas["RunCardOut"];
