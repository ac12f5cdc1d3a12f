/** What the dashboard reads from the server: each query's key (`app/queries.ts`) with its request. */
import { api, unwrap } from "../api/client";
import type {
  Demon,
  Evaluation,
  History,
  LiveViewInfo,
  Me,
  Protocol,
  Run,
  RunBrief,
  RunCard,
  Scenario,
  StreamHistory,
  StreamRun,
  Study,
  StudyDetail,
  Token,
  WorldRecord,
} from "../api/types";
import type { LearnerInfo } from "../lib/learners";
import { type StateErrors, latestErrors } from "../lib/state-errors";
import { type Query, keys } from "./queries";
import { VIEWER_KEY } from "./viewer-key";

const runPath = (runId: string) => ({ params: { path: { run_id: runId } } });

export const reads = {
  runs: (): Query<RunBrief[]> => ({ queryKey: keys.runs, queryFn: () => unwrap(api.GET("/api/runs")) }),
  run: (runId: string): Query<Run> => ({
    queryKey: keys.run(runId),
    queryFn: () => unwrap(api.GET("/api/runs/{run_id}", runPath(runId))),
  }),
  demons: (runId: string): Query<Demon[]> => ({
    queryKey: keys.demons(runId),
    queryFn: () => unwrap(api.GET("/api/runs/{run_id}/demons", runPath(runId))),
  }),
  learners: (): Query<LearnerInfo[]> => ({ queryKey: keys.learners, queryFn: () => unwrap(api.GET("/api/learners")) }),
  scenarios: (): Query<Scenario[]> => ({
    queryKey: keys.scenarios,
    queryFn: () => unwrap(api.GET("/api/scenarios")),
  }),
  worlds: (): Query<WorldRecord[]> => ({ queryKey: keys.worlds, queryFn: () => unwrap(api.GET("/api/worlds")) }),
  /** the live view, at this page's own address (`VIEWER_KEY`) */
  view: (): Query<LiveViewInfo> => ({
    queryKey: keys.view,
    queryFn: () => unwrap(api.GET("/api/view", { params: { query: { viewer: VIEWER_KEY } } })),
  }),
  /** the evaluations the server kept with the run (the latest of each demon), by demon */
  evaluations: (runId: string): Query<Record<string, Evaluation>> => ({
    queryKey: keys.evaluations(runId),
    queryFn: async () => {
      const kept = await unwrap(api.GET("/api/runs/{run_id}/evaluations", runPath(runId)));
      return Object.fromEntries(kept.map((evaluation) => [evaluation.demon, evaluation]));
    },
  }),
  /** every protocol job the server keeps, oldest first */
  protocols: (): Query<Protocol[]> => ({
    queryKey: keys.protocols,
    queryFn: () => unwrap(api.GET("/api/protocols")),
  }),
  protocol: (jobId: string): Query<Protocol> => ({
    queryKey: keys.protocol(jobId),
    queryFn: () => unwrap(api.GET("/api/protocols/{job_id}", { params: { path: { job_id: jobId } } })),
  }),
  /** the histories of some demons of a run, one request each */
  histories: (runId: string, demons: readonly string[]): Query<History[]> => ({
    queryKey: keys.histories(runId, demons),
    queryFn: () =>
      Promise.all(
        demons.map((name) =>
          unwrap(api.GET("/api/runs/{run_id}/demons/{name}/history", { params: { path: { run_id: runId, name } } })),
        ),
      ),
  }),
  /** the demons' latest RMSVE and RMSPBE: each history's last row (null when the run records none) */
  stateErrors: (runId: string, demons: readonly string[]): Query<Map<string, StateErrors> | null> => ({
    queryKey: keys.stateErrors(runId, demons),
    queryFn: async () =>
      latestErrors(
        await Promise.all(
          demons.map((name) =>
            unwrap(
              api.GET("/api/runs/{run_id}/demons/{name}/history", {
                params: { path: { run_id: runId, name }, query: { limit: 1 } },
              }),
            ),
          ),
        ),
      ),
  }),
  streams: (): Query<StreamRun[]> => ({ queryKey: keys.streams, queryFn: () => unwrap(api.GET("/api/streams")) }),
  streamHistory: (
    streamId: string,
    sensors: readonly string[],
    demons: readonly string[],
    last: number,
  ): Query<StreamHistory> => ({
    queryKey: keys.streamHistory(streamId, sensors, demons),
    queryFn: () =>
      unwrap(
        api.GET("/api/streams/{stream_id}/history", {
          params: {
            path: { stream_id: streamId },
            query: { sensors: sensors.join(","), demons: demons.join(","), last },
          },
        }),
      ),
  }),
  streamDemons: (streamId: string): Query<Demon[]> => ({
    queryKey: keys.streamDemons(streamId),
    queryFn: () => unwrap(api.GET("/api/streams/{stream_id}/demons", { params: { path: { stream_id: streamId } } })),
  }),
  studies: (): Query<Study[]> => ({ queryKey: keys.studies, queryFn: () => unwrap(api.GET("/api/studies")) }),
  study: (studyId: string): Query<StudyDetail> => ({
    queryKey: keys.study(studyId),
    queryFn: () => unwrap(api.GET("/api/studies/{study_id}", { params: { path: { study_id: studyId } } })),
  }),
  me: (): Query<Me> => ({ queryKey: keys.me, queryFn: () => unwrap(api.GET("/api/me")) }),
  overview: (): Query<RunCard[]> => ({ queryKey: keys.overview, queryFn: () => unwrap(api.GET("/api/overview")) }),
  tokens: (): Query<Token[]> => ({ queryKey: keys.tokens, queryFn: () => unwrap(api.GET("/api/tokens")) }),
};
