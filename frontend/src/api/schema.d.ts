/**
 * The Horde Lab API, generated from the server's OpenAPI schema by `npm run gen:api`.
 * Do not edit: change the pydantic models in backend/horde and regenerate.
 */

export interface paths {
    "/api/health": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /**
         * Server health
         * @description Answered on the event loop itself (no worker thread to wait for): a measure of its responsiveness.
         */
        get: operations["health_api_health_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/lab": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** The textbook lab's experiments */
        get: operations["list_lab_api_lab_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/lab/{experiment_id}/prepare": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /**
         * An experiment with a set-up applied
         * @description The spec to launch: 422 naming the set-up field (`body.setup.<name>`) whose value the field refuses.
         */
        post: operations["prepare_api_lab__experiment_id__prepare_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/learners": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /**
         * The learners a demon may name, with their parameters and needs
         * @description Declared by the engine's learner modules (`horde.core.learners`), in the order of their names.
         */
        get: operations["list_learners_api_learners_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/me": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /**
         * Who this request acts as (its token's role)
         * @description 401 for a token that is not this server's or was revoked (the dashboard then drops it).
         */
        get: operations["who_am_i_api_me_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/overview": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** Every run as a card: owner, status, counters, a sparkline of its first demons */
        get: operations["overview_api_overview_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/protocols": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** The protocol jobs (running and recent) */
        get: operations["list_protocols_api_protocols_get"];
        put?: never;
        /**
         * Run a scenario's protocol in the background
         * @description The body is a RunSpec, or a template {scenario, seed, protocol: {trials, episodes}, ...}. One protocol runs at a
         *     time (429 while one runs). Poll GET /api/protocols/{id} for progress and results.
         */
        post: operations["start_protocol_api_protocols_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/protocols/{job_id}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A protocol job: progress, then results */
        get: operations["get_protocol_api_protocols__job_id__get"];
        put?: never;
        post?: never;
        /** Cancel a running protocol job, or forget a finished one */
        delete: operations["cancel_protocol_api_protocols__job_id__delete"];
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/protocols/{job_id}/export": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A protocol job's results: per demon prediction, truth ± stderr, error, thesis, test-run counts */
        get: operations["export_protocol_api_protocols__job_id__export_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** List the runs */
        get: operations["list_runs_api_runs_get"];
        put?: never;
        /**
         * Create a run
         * @description The body is a RunSpec, or a template: {scenario, world, seed, ...overrides} (a body with a `scenario` key, or
         *     whose `world` is a string naming a stored world). The run is the first trial of its protocol, seeded as `horde
         *     run` seeds it; it belongs to the requester. The run's worker validates and builds it (a 422 names the field as
         *     always). 404: unknown scenario or world; 409: too many runs.
         */
        post: operations["create_run_api_runs_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs/import": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /**
         * Import a snapshot as a new run
         * @description The new run continues exactly where the snapshot was taken (paused, or finished); it belongs to the
         *     requester. 422 when the arrays do not fit the spec; 409 when the server holds as many runs as it allows.
         */
        post: operations["import_snapshot_api_runs_import_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs/{run_id}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A run */
        get: operations["get_run_api_runs__run_id__get"];
        put?: never;
        post?: never;
        /** Delete a run */
        delete: operations["delete_run_api_runs__run_id__delete"];
        options?: never;
        head?: never;
        /**
         * Change a run's speed or behaviour policy
         * @description `hz: null` runs as fast as possible; a field left out is unchanged.
         */
        patch: operations["patch_run_api_runs__run_id__patch"];
        trace?: never;
    };
    "/api/runs/{run_id}/demons": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A run's demons */
        get: operations["list_demons_api_runs__run_id__demons_get"];
        put?: never;
        /**
         * Add a demon to a run (live runs too)
         * @description The other demons keep their weights; traces restart. 409 when the name is taken or the run is finished or
         *     failed; 422 when the demon does not fit the run (unknown demon or sensor, a cycle).
         */
        post: operations["add_demon_api_runs__run_id__demons_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs/{run_id}/demons/{name}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** One demon */
        get: operations["get_demon_api_runs__run_id__demons__name__get"];
        put?: never;
        post?: never;
        /**
         * Remove a demon from a run
         * @description 409 when other demons or the behaviour depend on it, or the run is finished or failed.
         */
        delete: operations["remove_demon_api_runs__run_id__demons__name__delete"];
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs/{run_id}/demons/{name}/history": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A demon's prediction, cumulant, TD error, RUPEE and UDE over time */
        get: operations["get_history_api_runs__run_id__demons__name__history_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs/{run_id}/demons/{name}/values": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /**
         * A demon's prediction over the world
         * @description The prediction at the centres of a resolution x resolution grid, with the current weights (read by the run's
         *     worker); on a world of discrete states with known transitions (the chains, Baird's star), at every state beside
         *     the true values and the TD fixed point (`kind` "states"; `resolution` is not used). 409 when the run's worker is
         *     gone.
         */
        get: operations["get_values_api_runs__run_id__demons__name__values_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs/{run_id}/evaluate": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /**
         * Monte-Carlo truth of a demon's question vs its prediction
         * @description Rolls the demon's target policy out with frozen weights (its own generator: the run is not disturbed), as
         *     the run's world allows (its `evaluation`): on the grid from `from` (default: the world's start), on a
         *     Gymnasium world from the agent's current state. 422 when `from` lies outside the world or in an obstacle, is
         *     given on a world without points, or the demon's question cannot be rolled out there, or when the rollouts do
         *     not finish within HORDE_EVALUATION_SECONDS (at `episodes`: ask for fewer, or a smaller `cap`); 429 when two
         *     evaluations are running already. A client that hangs up ends its evaluation (the grid's rollouts stop at
         *     their next chunk). The answer is kept with the run (the latest of each demon; a reset drops them).
         */
        post: operations["evaluate_api_runs__run_id__evaluate_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs/{run_id}/evaluations": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** The run's kept evaluations, the latest of each demon */
        get: operations["evaluations_api_runs__run_id__evaluations_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs/{run_id}/export/history": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A run's history: step, demon, prediction, cumulant, delta, RUPEE, UDE for every kept row */
        get: operations["export_history_api_runs__run_id__export_history_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs/{run_id}/export/spec": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A run's spec as a TOML scenario file (horde run reads it back) */
        get: operations["export_spec_api_runs__run_id__export_spec_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs/{run_id}/pause": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /**
         * Pause a running run
         * @description Takes a snapshot. 409 unless the run is running.
         */
        post: operations["pause_run_api_runs__run_id__pause_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs/{run_id}/reset": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /**
         * Reset a run to its first step
         * @description Fresh weights and generator, the current demons; the status becomes created. The run's kept evaluations
         *     are dropped (they described the old weights).
         */
        post: operations["reset_run_api_runs__run_id__reset_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs/{run_id}/snapshot": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /**
         * Export a run: weights, traces, generator state, counters, world state
         * @description The run's worker writes the document (its weights never cross into the server as objects). 409 when the
         *     run's worker is gone (a run that failed because its worker died).
         */
        get: operations["export_snapshot_api_runs__run_id__snapshot_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs/{run_id}/start": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /**
         * Start (or resume) a run
         * @description 409 unless the run is created or paused.
         */
        post: operations["start_run_api_runs__run_id__start_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs/{run_id}/state": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** The live state of a run */
        get: operations["get_state_api_runs__run_id__state_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/runs/{run_id}/step": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /**
         * Take steps on a run that is not running
         * @description Default 1 step. 409 when the run is running, finished or failed.
         */
        post: operations["step_run_api_runs__run_id__step_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scenarios": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** List the scenarios */
        get: operations["list_scenarios_api_scenarios_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/scenarios/{name}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /**
         * A scenario's RunSpec
         * @description 409 when the file exists but does not load (the message names file, line and field).
         */
        get: operations["get_scenario_api_scenarios__name__get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/streams": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** Every stream run, oldest first, with its counters and predictions */
        get: operations["list_streams_api_streams_get"];
        put?: never;
        /** Start a stream run (a run spec whose world is of kind 'stream') */
        post: operations["create_stream_api_streams_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/streams/import": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /** A new stream run from a snapshot: it learns the next record as the exported run would have */
        post: operations["import_stream_api_streams_import_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/streams/{stream_id}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A stream run's counters and predictions */
        get: operations["get_stream_api_streams__stream_id__get"];
        put?: never;
        post?: never;
        /** Stop and forget a stream run */
        delete: operations["delete_stream_api_streams__stream_id__delete"];
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/streams/{stream_id}/demons": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /**
         * A stream run's demon table
         * @description Each demon's prediction at the last observation and its error measures (null where it diverged).
         */
        get: operations["get_stream_demons_api_streams__stream_id__demons_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/streams/{stream_id}/history": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /**
         * The recent records' sensors, and each demon's prediction beside the return that followed
         * @description The strip chart of the nexting paper: the last `last` good records (the server keeps the last 2,000, fewer
         *     for Hordes of more than 2,000 demons) with each chosen demon's prediction made at the time beside the
         *     realised discounted return computed afterwards from the stream.
         */
        get: operations["get_stream_history_api_streams__stream_id__history_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/streams/{stream_id}/phase-plane": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A demon's value map over two sensors (the others held at their last readings), with the trail */
        get: operations["get_phase_plane_api_streams__stream_id__phase_plane_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/streams/{stream_id}/records": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /** Learn a batch of records, in order (all or nothing) */
        post: operations["push_records_api_streams__stream_id__records_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/streams/{stream_id}/snapshot": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A stream run's learner, to import elsewhere */
        get: operations["get_stream_snapshot_api_streams__stream_id__snapshot_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/studies": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** Every study (running, finished, interrupted) */
        get: operations["list_studies_api_studies_get"];
        put?: never;
        /**
         * Start a parameter study in the background
         * @description The body is a study, as in a study file: a `scenario` name (or a `base` run spec), `axes` (a field path and its
         *     values each), `sample`, `runs` per configuration and `measure`. Every axis is checked before any task starts: an
         *     unknown path, a value the field refuses, or a grid past the bounds is a 422 located at the axis. One study runs
         *     at a time (429 while one runs).
         */
        post: operations["start_study_api_studies_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/studies/{study_id}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A study: progress, then results per configuration */
        get: operations["get_study_api_studies__study_id__get"];
        put?: never;
        post?: never;
        /** Cancel a running study (finished tasks are kept), or delete a study that is not running */
        delete: operations["cancel_study_api_studies__study_id__delete"];
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/studies/{study_id}/export": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A study's results as CSV (a row per configuration and demon), its learning curves as CSV (a row per configuration, demon and checkpoint) or JSON (as horde study --json) */
        get: operations["export_study_api_studies__study_id__export_get"];
        put?: never;
        post?: never;
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/studies/{study_id}/resume": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        /** Run the unfinished tasks of a cancelled, failed or interrupted study */
        post: operations["resume_study_api_studies__study_id__resume_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/tokens": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /**
         * The tokens in use (the teacher's)
         * @description Their ids, names and roles, never their secrets. 401 without a token, 403 for a student's or viewer's.
         */
        get: operations["list_tokens_api_tokens_get"];
        put?: never;
        /**
         * Issue a token for a student or a viewer (the teacher's)
         * @description 403 unless the requester holds HORDE_TOKEN; 409 on a server without HORDE_TOKEN, or when a token of that
         *     name was issued before (a name names one holder, as the owner of what they make, even once revoked); 422 for
         *     an unknown role or a name that is empty, too long or 'teacher'.
         */
        post: operations["issue_token_api_tokens_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/tokens/{token_id}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        get?: never;
        put?: never;
        post?: never;
        /**
         * Revoke a token (the teacher's)
         * @description Its holder is refused from now on (401), on the API, its WebSockets and the live view; what they made
         *     stays, under their name. 404 for an unknown or already revoked token.
         */
        delete: operations["revoke_token_api_tokens__token_id__delete"];
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/view": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** Whether and where the live view listens (for one dashboard tab, with `viewer`) */
        get: operations["get_view_api_view_get"];
        put?: never;
        /** Show a run in one dashboard tab's live view */
        post: operations["show_run_api_view_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/worlds": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** List the stored worlds */
        get: operations["list_worlds_api_worlds_get"];
        put?: never;
        /**
         * Store a new world
         * @description 409 when a world of that name exists already, or the store holds as many worlds as allowed.
         */
        post: operations["create_world_api_worlds_post"];
        delete?: never;
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
    "/api/worlds/{name}": {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        /** A stored world */
        get: operations["get_world_api_worlds__name__get"];
        /**
         * Create or replace a stored world
         * @description 200 when it replaced a world, 201 when it created one. The body's name, if given, must match.
         */
        put: operations["put_world_api_worlds__name__put"];
        post?: never;
        /** Delete a stored world */
        delete: operations["delete_world_api_worlds__name__delete"];
        options?: never;
        head?: never;
        patch?: never;
        trace?: never;
    };
}
export type webhooks = Record<string, never>;
export interface components {
    schemas: {
        /** AddExpr */
        "AddExpr-Input": {
            /** Add */
            add: (number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Input"] | components["schemas"]["MulExpr-Input"] | components["schemas"]["MinExpr-Input"] | components["schemas"]["MaxExpr-Input"] | components["schemas"]["IfExpr-Input"])[];
        };
        /** AddExpr */
        "AddExpr-Output": {
            /** Add */
            add: (number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Output"] | components["schemas"]["MulExpr-Output"] | components["schemas"]["MinExpr-Output"] | components["schemas"]["MaxExpr-Output"] | components["schemas"]["IfExpr-Output"])[];
        };
        /** AgentOut */
        AgentOut: {
            /** X */
            x: number;
            /** Y */
            y: number;
        };
        /**
         * Aggregate
         * @description State aggregation (Sutton & Barto 2018, section 9.3) as a table: the readings first..last of the table's
         *     sensor in groups of `size` consecutive ones, one feature per group (readings outside: the nearest group).
         */
        Aggregate: {
            /**
             * First
             * @description the first reading of the first group
             */
            first: number;
            /**
             * Last
             * @description the last reading of the last group
             */
            last: number;
            /**
             * Size
             * @description readings per group
             */
            size: number;
        };
        /** AxisOut */
        AxisOut: {
            /** High */
            high: number;
            /** Low */
            low: number;
            /** Sensor */
            sensor: string;
        };
        /**
         * AxisSpec
         * @description One field to vary and the values it takes.
         */
        AxisSpec: {
            /**
             * Path
             * @description a dotted field path of the run spec, e.g. learning.alpha or demons.*.learner
             */
            path: string;
            /** Values */
            values: (number | string | boolean)[];
        };
        /**
         * BandOut
         * @description A mean over runs per checkpoint with its 95 % bootstrap interval.
         */
        BandOut: {
            /** High */
            high: (number | null)[];
            /** Low */
            low: (number | null)[];
            /** Mean */
            mean: (number | null)[];
        };
        /**
         * BehaviourSpec
         * @description The behaviour policy of a run: uniform, fixed, or greedy/softmax/epsilon_greedy over a control demon.
         */
        BehaviourSpec: {
            /**
             * Actions
             * @description sign: [action where negative, action where >= 0]
             */
            actions?: number[] | null;
            /** Demon */
            demon?: string | null;
            /**
             * Epsilon
             * @default 0.1
             */
            epsilon: number;
            /**
             * Kind
             * @default uniform
             * @enum {string}
             */
            kind: "uniform" | "fixed" | "greedy" | "softmax" | "epsilon_greedy" | "sign";
            /** Probabilities */
            probabilities?: number[] | null;
            /**
             * Sensor
             * @description sign: the sensor whose sign chooses the action
             */
            sensor?: string | null;
            /**
             * Temperature
             * @default 1
             */
            temperature: number;
        };
        /** Color */
        Color: {
            /** Name */
            name: string;
            /** Probability */
            probability: number;
            /**
             * Value
             * @description the value of the color:<indicator> sensor while inside
             */
            value: number;
        };
        /** Condition */
        Condition: {
            /** Demon */
            demon: string;
            /** Thresholds */
            thresholds: number[];
        };
        /** Counts */
        Counts: {
            /** Negative */
            negative: number;
            /** None */
            none: number;
            /** Positive */
            positive: number;
        };
        /** CountsOut */
        CountsOut: {
            /** Negative */
            negative: number;
            /** None */
            none: number;
            /** Positive */
            positive: number;
        };
        /**
         * DemonFamily
         * @description One entry that expands into a demon for every combination of its lists (their product).
         *
         *     `demon` is a demon written as usual, in which any "{var}" stands for the values of the list `var`
         *     of `over`; `name` is the pattern of the demons' names, such as "{sensor}_g{gamma}" (characters a
         *     name cannot hold, such as the colon of "in:zone1", become "_"). A 422 about a family names the field
         *     and the rule, never the pattern or a demon name made of it (they are input).
         */
        DemonFamily: {
            /**
             * Demon
             * @description a demon without its name; "{var}" in any string takes the values
             */
            demon: {
                [key: string]: unknown;
            };
            /**
             * Name
             * @description the name pattern, e.g. "{sensor}_g{gamma}"
             */
            name: string;
            /**
             * Over
             * @description the lists whose product the family expands into
             */
            over: {
                [key: string]: (string | number)[];
            };
        };
        /** DemonMetricsOut */
        DemonMetricsOut: {
            /** Cumulant */
            cumulant: number | null;
            /** Delta */
            delta: number | null;
            /** Diverged */
            diverged: boolean;
            /** Rupee */
            rupee: number | null;
            /**
             * Step Size
             * @description the step size the demon takes now, in alpha's units: alpha for a constant step size; for autostep and tidbd the sum of its per-weight step sizes over the active features
             */
            step_size?: number | null;
            /** Ude */
            ude: number | null;
        };
        /** DemonOut */
        DemonOut: {
            /**
             * Colour
             * @description the demon's colour in the dashboard and the live view (#rrggbb)
             */
            colour: string;
            /**
             * Control
             * @description a control demon (its target policy acts on its own action values)
             */
            control: boolean;
            metrics: components["schemas"]["DemonMetricsOut"];
            /** Name */
            name: string;
            /** Prediction */
            prediction: number | null;
            spec: components["schemas"]["DemonSpec-Output"];
        };
        /**
         * DemonResultOut
         * @description One demon's line of a protocol's results (as `horde run --json` writes it).
         */
        DemonResultOut: {
            /** @description where the test runs ended (control protocols) */
            counts?: components["schemas"]["CountsOut"] | null;
            /**
             * Error
             * @description prediction - truth
             */
            error: number | null;
            /** Name */
            name: string;
            /**
             * Prediction
             * @description the prediction at the start, mean over trials (null: diverged)
             */
            prediction: number | null;
            /**
             * Thesis
             * @description the thesis's number, where it has one
             */
            thesis: number | null;
            /**
             * Truth
             * @description Monte-Carlo truth at the start, mean over trials
             */
            truth: number | null;
            /** Truth Stderr */
            truth_stderr: number | null;
        };
        /**
         * DemonSpec
         * @description A question (policy, cumulant, outcome, continuation) and its answer (features, learner, step sizes).
         */
        "DemonSpec-Input": {
            /**
             * Alpha
             * @description step size before division by the number of active features
             */
            alpha?: number | null;
            /**
             * Alpha W
             * @description step size of the secondary weights, also divided by the active count
             */
            alpha_w?: number | null;
            /**
             * Continuation
             * @default 1
             */
            continuation: number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Input"] | components["schemas"]["MulExpr-Input"] | components["schemas"]["MinExpr-Input"] | components["schemas"]["MaxExpr-Input"] | components["schemas"]["IfExpr-Input"];
            /**
             * Cumulant
             * @default 0
             */
            cumulant: number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Input"] | components["schemas"]["MulExpr-Input"] | components["schemas"]["MinExpr-Input"] | components["schemas"]["MaxExpr-Input"] | components["schemas"]["IfExpr-Input"];
            /**
             * Discount
             * @default 1
             */
            discount: number;
            /** @description defaults to the run's features */
            features?: components["schemas"]["FeatureSpec"] | null;
            /**
             * Initial Weights
             * @description the weights the demon starts from (and a run reset restores), one per feature (gq: per feature of every action's block, action by action); default all 0
             */
            initial_weights?: number[] | null;
            /** Lambda */
            lambda?: number | null;
            /**
             * Learner
             * @description gq: action values (GQ(lambda)); the others learn state values (GET /api/learners lists them)
             * @default gq
             * @enum {string}
             */
            learner: "etd" | "gq" | "gtd" | "gtd1" | "gtd2" | "td" | "tdrc" | "true_online_gtd" | "true_online_td";
            /**
             * Meta Step
             * @description meta step size of autostep (mu) or tidbd (theta); defaults to [learning]
             */
            meta_step?: number | null;
            /** Name */
            name: string;
            /**
             * Outcome
             * @default 0
             */
            outcome: number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Input"] | components["schemas"]["MulExpr-Input"] | components["schemas"]["MinExpr-Input"] | components["schemas"]["MaxExpr-Input"] | components["schemas"]["IfExpr-Input"];
            /**
             * Parameters
             * @description the learner's own numbers beyond alpha, alpha_w and lambda, as it declares them (GET /api/learners); each defaults to its declared value
             */
            parameters?: {
                [key: string]: number;
            } | null;
            policy?: components["schemas"]["PolicySpec"];
            /**
             * Reset
             * @default never
             * @enum {string}
             */
            reset: "never" | "episode";
            /**
             * Step Size
             * @description constant (alpha as given), autostep or tidbd (per-weight step sizes adapted online, starting from alpha); defaults to the run's [learning] step_size
             */
            step_size?: ("constant" | "autostep" | "tidbd") | null;
        };
        /**
         * DemonSpec
         * @description A question (policy, cumulant, outcome, continuation) and its answer (features, learner, step sizes).
         */
        "DemonSpec-Output": {
            /**
             * Alpha
             * @description step size before division by the number of active features
             */
            alpha?: number | null;
            /**
             * Alpha W
             * @description step size of the secondary weights, also divided by the active count
             */
            alpha_w?: number | null;
            /**
             * Continuation
             * @default 1
             */
            continuation: number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Output"] | components["schemas"]["MulExpr-Output"] | components["schemas"]["MinExpr-Output"] | components["schemas"]["MaxExpr-Output"] | components["schemas"]["IfExpr-Output"];
            /**
             * Cumulant
             * @default 0
             */
            cumulant: number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Output"] | components["schemas"]["MulExpr-Output"] | components["schemas"]["MinExpr-Output"] | components["schemas"]["MaxExpr-Output"] | components["schemas"]["IfExpr-Output"];
            /**
             * Discount
             * @default 1
             */
            discount: number;
            /** @description defaults to the run's features */
            features?: components["schemas"]["FeatureSpec"] | null;
            /**
             * Initial Weights
             * @description the weights the demon starts from (and a run reset restores), one per feature (gq: per feature of every action's block, action by action); default all 0
             */
            initial_weights?: number[] | null;
            /** Lambda */
            lambda?: number | null;
            /**
             * Learner
             * @description gq: action values (GQ(lambda)); the others learn state values (GET /api/learners lists them)
             * @default gq
             * @enum {string}
             */
            learner: "etd" | "gq" | "gtd" | "gtd1" | "gtd2" | "td" | "tdrc" | "true_online_gtd" | "true_online_td";
            /**
             * Meta Step
             * @description meta step size of autostep (mu) or tidbd (theta); defaults to [learning]
             */
            meta_step?: number | null;
            /** Name */
            name: string;
            /**
             * Outcome
             * @default 0
             */
            outcome: number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Output"] | components["schemas"]["MulExpr-Output"] | components["schemas"]["MinExpr-Output"] | components["schemas"]["MaxExpr-Output"] | components["schemas"]["IfExpr-Output"];
            /**
             * Parameters
             * @description the learner's own numbers beyond alpha, alpha_w and lambda, as it declares them (GET /api/learners); each defaults to its declared value
             */
            parameters?: {
                [key: string]: number;
            } | null;
            policy?: components["schemas"]["PolicySpec"];
            /**
             * Reset
             * @default never
             * @enum {string}
             */
            reset: "never" | "episode";
            /**
             * Step Size
             * @description constant (alpha as given), autostep or tidbd (per-weight step sizes adapted online, starting from alpha); defaults to the run's [learning] step_size
             */
            step_size?: ("constant" | "autostep" | "tidbd") | null;
        };
        /**
         * EncodedArray
         * @description A numpy array: its dtype, shape and the base64 of its little-endian bytes.
         */
        EncodedArray: {
            /** Data */
            data: string;
            /**
             * Dtype
             * @enum {string}
             */
            dtype: "float64" | "float32" | "int64" | "bool";
            /** Shape */
            shape: number[];
        };
        /**
         * ErrorOut
         * @description A refused request: 401, 404, 409 and 429 carry one message.
         */
        ErrorOut: {
            /** Detail */
            detail: string;
        };
        /**
         * EvaluateIn
         * @description A Monte-Carlo evaluation of one demon's question, as the run's world allows (`RunOut.evaluation`).
         *
         *     On the grid ("grid") from a point `from` = [x, y], by default the world's start (the centre of a start
         *     rectangle); on a Gymnasium world ("rollouts") from the agent's current state, `from` left out.
         */
        EvaluateIn: {
            /**
             * Cap
             * @description steps per rollout at most (default: the protocol's)
             */
            cap?: number | null;
            /** Demon */
            demon: string;
            /**
             * Episodes
             * @description rollouts
             * @default 100
             */
            episodes: number;
            /**
             * From
             * @description [x, y] on the grid (default: the world's start); left out on a Gymnasium world
             */
            from?: number[] | null;
            /** Seed */
            seed?: number | null;
        };
        /** EvaluationOut */
        EvaluationOut: {
            /** Cap */
            cap: number;
            /**
             * Capped
             * @description rollouts still running at the cap
             */
            capped: number;
            /** Demon */
            demon: string;
            /** Episodes */
            episodes: number;
            /**
             * Error
             * @description prediction - truth
             */
            error: number | null;
            /**
             * Exact
             * @description the exact answer at `from` on a small lattice world (no noise), else null
             */
            exact?: number | null;
            /**
             * From
             * @description the point [x, y] evaluated from on the grid; elsewhere the sensors at the agent's state the rollouts began from (one per sensor, in the world's order)
             */
            from: number[];
            /** Prediction */
            prediction: number | null;
            /** Seed */
            seed: number;
            /** Stderr */
            stderr: number | null;
            /**
             * Step
             * @description the run's step whose weights were evaluated (null in evaluations kept before runs said so)
             */
            step?: number | null;
            /**
             * Truth
             * @description mean realised return over the rollouts
             */
            truth: number | null;
        };
        /**
         * EvaluationSpec
         * @description Monte-Carlo truth at the start point after each trial.
         */
        EvaluationSpec: {
            /**
             * Cap
             * @description rollout length limit
             * @default 10000
             */
            cap: number;
            /**
             * Demons
             * @description which demons; default all prediction demons
             */
            demons?: string[] | null;
            /**
             * Rollouts
             * @default 1000
             */
            rollouts: number;
            /**
             * States
             * @description Gymnasium worlds: test states, from a run of the behaviour after learning
             * @default 20
             */
            states: number;
        };
        /**
         * EvaluationSupportOut
         * @description What POST /api/runs/{id}/evaluate can do in this run's world.
         */
        EvaluationSupportOut: {
            /**
             * Kind
             * @description grid: from a point [x, y], and a value map over the world; rollouts: from the agent's current state, no value map; none: no evaluation (`note` says why)
             * @enum {string}
             */
            kind: "grid" | "rollouts" | "none";
            /**
             * Note
             * @description one sentence: what an evaluation is here, or why there is none
             */
            note: string;
        };
        /** EventOut */
        EventOut: {
            /** Episode */
            episode: number;
            /**
             * Kind
             * @enum {string}
             */
            kind: "status" | "episode" | "demon" | "error";
            /** Message */
            message: string;
            /** Seq */
            seq: number;
            /** Step */
            step: number;
            /** Value */
            value?: number | null;
        };
        /**
         * FeatureSpec
         * @description How a state is coded into sparse features, each with a value (DESIGN section 3).
         */
        FeatureSpec: {
            /** @description table: state aggregation, written for the table (which is then made from it) */
            aggregate?: components["schemas"]["Aggregate"] | null;
            /**
             * Centres
             * @description rbf: radial basis functions per input, evenly spaced over [0, 1]: centres^inputs features
             */
            centres?: number | null;
            condition?: components["schemas"]["Condition"] | null;
            /**
             * Kind
             * @default stripes
             * @enum {string}
             */
            kind: "stripes" | "tiles" | "grid" | "constant" | "sensors" | "table" | "polynomial" | "fourier" | "rbf" | "linear";
            /**
             * Order
             * @description polynomial, fourier: the highest exponent (or frequency) of each input: (order + 1)^inputs features
             */
            order?: number | null;
            /**
             * Parts
             * @description stripes: columns, rows, diagonals
             * @default 5
             */
            parts: number;
            /**
             * Sensor
             * @description table: the discrete sensor whose reading (0, 1, 2, ...) picks a row of the table
             */
            sensor?: string | null;
            /**
             * Sensors
             * @description sensors: each tiled on its own; polynomial, fourier, rbf, linear: the basis' inputs, each scaled from its range [low, high] to [0, 1]
             */
            sensors?: components["schemas"]["TiledSensor"][] | null;
            /**
             * Size
             * @description sensors: the hash table's size (features besides the bias)
             */
            size?: number | null;
            /**
             * Table
             * @description table: per reading of the sensor, its active feature indices (all rows of one length); an index listed twice is a feature of value 2 there (Baird's counterexample)
             */
            table?: number[][] | null;
            /**
             * Tiles
             * @description tiles, grid, sensors: tiles per dimension
             * @default 8
             */
            tiles: number;
            /**
             * Tilings
             * @description tiles, sensors: number of offset tilings
             * @default 8
             */
            tilings: number;
            /**
             * Values
             * @description table: the value of each index listed, row by row (default 1): Boyan's chain, Sutton et al. 2009's inverted and dependent features
             */
            values?: number[][] | null;
            /**
             * Width
             * @description rbf: sigma of each Gaussian, in units of the scaled inputs (default: the spacing of the centres)
             */
            width?: number | null;
        };
        /**
         * GymnasiumWorldSpec
         * @description An installed Gymnasium environment with a `Box` (or `Discrete`) observation and a `Discrete` action space.
         *
         *     Its sensors are the observation's components (named and ranged by `horde.worlds.gym_spaces`), then
         *     `reward`, `terminated` and `truncated`, read after every step (0 at an episode's first state). They are
         *     resolved outside validation (`horde.worlds.gym_spaces.resolve_world`): `resolved` says whether they are.
         */
        GymnasiumWorldSpec: {
            /**
             * Id
             * @description a registered environment id, e.g. MountainCar-v0 (or horde/Baird-v0, Baird's counterexample)
             */
            id: string;
            /**
             * Kind
             * @constant
             */
            kind: "gymnasium";
            /**
             * Max Steps
             * @description truncate episodes here (default: the environment's own limit)
             */
            max_steps?: number | null;
            /** Name */
            name?: string | null;
            /**
             * States
             * @description a random walk's number of non-terminal states (horde/RandomWalk*-v0; default the id's own)
             */
            states?: number | null;
        };
        /** HTTPValidationError */
        HTTPValidationError: {
            /** Detail */
            detail?: components["schemas"]["ValidationError"][];
        };
        /** HealthOut */
        HealthOut: {
            /** Runs */
            runs: number;
            /**
             * Status
             * @default ok
             * @constant
             */
            status: "ok";
            /** Version */
            version: string;
        };
        /**
         * HistoryOut
         * @description A demon's recent history, oldest first (null before the demon joined).
         *
         *     Rows are sampled: at most one per `every` steps and one per HORDE_HISTORY_INTERVAL seconds (default
         *     5 ms), so a run paced by hz has a row per step and a run at full speed a row every few milliseconds.
         */
        HistoryOut: {
            /**
             * Capacity
             * @description rows kept at most
             */
            capacity: number;
            /** Cumulant */
            cumulant: (number | null)[];
            /** Delta */
            delta: (number | null)[];
            /** Demon */
            demon: string;
            /**
             * Every
             * @description steps between two rows, at least
             */
            every: number;
            /** Prediction */
            prediction: (number | null)[];
            /**
             * Rmspbe
             * @description as rmsve: the root of the projected Bellman error with the demon's own lambda, under the same weighting (0 at the TD fixed point)
             */
            rmspbe?: (number | null)[] | null;
            /**
             * Rmsve
             * @description on a world of discrete states with known transitions (the chains, Baird's star): the RMS error of the demon's values over the states against the true values, weighted by the behaviour's distribution over states (on-policy: the book's mu), measured at most every 0.1 s while the run runs and at the last row of a step or pause (rows between carry the latest measurement); null elsewhere (no states to measure over), null entries for a demon without a truth (action values, a question that reads other demons)
             */
            rmsve?: (number | null)[] | null;
            /** Rupee */
            rupee: (number | null)[];
            /** Step */
            step: number[];
            /** Ude */
            ude: (number | null)[];
        };
        /** IfExpr */
        "IfExpr-Input": {
            /** Else */
            else: number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Input"] | components["schemas"]["MulExpr-Input"] | components["schemas"]["MinExpr-Input"] | components["schemas"]["MaxExpr-Input"] | components["schemas"]["IfExpr-Input"];
            /**
             * If
             * @description counts as true where it is not 0
             */
            if: number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Input"] | components["schemas"]["MulExpr-Input"] | components["schemas"]["MinExpr-Input"] | components["schemas"]["MaxExpr-Input"] | components["schemas"]["IfExpr-Input"];
            /** Then */
            then: number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Input"] | components["schemas"]["MulExpr-Input"] | components["schemas"]["MinExpr-Input"] | components["schemas"]["MaxExpr-Input"] | components["schemas"]["IfExpr-Input"];
        };
        /** IfExpr */
        "IfExpr-Output": {
            /** Else */
            else: number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Output"] | components["schemas"]["MulExpr-Output"] | components["schemas"]["MinExpr-Output"] | components["schemas"]["MaxExpr-Output"] | components["schemas"]["IfExpr-Output"];
            /**
             * If
             * @description counts as true where it is not 0
             */
            if: number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Output"] | components["schemas"]["MulExpr-Output"] | components["schemas"]["MinExpr-Output"] | components["schemas"]["MaxExpr-Output"] | components["schemas"]["IfExpr-Output"];
            /** Then */
            then: number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Output"] | components["schemas"]["MulExpr-Output"] | components["schemas"]["MinExpr-Output"] | components["schemas"]["MaxExpr-Output"] | components["schemas"]["IfExpr-Output"];
        };
        /** IndicatorReward */
        IndicatorReward: {
            /** Indicator */
            indicator: string;
            /**
             * Values
             * @description terminal reward per colour of the indicator
             */
            values: {
                [key: string]: number;
            };
        };
        /** LabExperimentOut */
        LabExperimentOut: {
            /** Id */
            id: string;
            /**
             * Kind
             * @description run: a scenario launched live; study: a figure
             * @enum {string}
             */
            kind: "run" | "study";
            /**
             * See
             * @description what the class should see
             */
            see: string;
            /** Setup */
            setup: components["schemas"]["LabSettingOut"][];
            /**
             * Source
             * @description the scenario's or the study file's name
             */
            source: string;
            /** Title */
            title: string;
        };
        /** LabPreparedOut */
        LabPreparedOut: {
            /**
             * Kind
             * @enum {string}
             */
            kind: "run" | "study";
            /**
             * Spec
             * @description a RunSpec (POST /api/runs) or a StudySpec (POST /api/studies)
             */
            spec: {
                [key: string]: unknown;
            };
        };
        /** LabSettingOut */
        LabSettingOut: {
            /** Name */
            name: string;
            /**
             * Value
             * @description as shipped: one number for a run, numbers separated by commas for a figure
             */
            value: string;
        };
        /** LabSetupIn */
        LabSetupIn: {
            /**
             * Setup
             * @description alpha, lambda, order, runs: as typed
             */
            setup?: {
                [key: string]: string;
            };
        };
        /** LearnerOut */
        LearnerOut: {
            /**
             * Action Values
             * @description learns action values: may follow its own greedy / softmax policy
             */
            action_values: boolean;
            /**
             * Name
             * @description what a demon writes: learner = NAME
             */
            name: string;
            /** Paper */
            paper: string;
            /**
             * Parameters
             * @description its own numbers, set in a demon's `parameters`
             */
            parameters: components["schemas"]["ParameterOut"][];
            /**
             * Secondary
             * @description keeps a second weight vector learned at alpha_w
             */
            secondary: boolean;
            /**
             * Step Sizes
             * @description the step-size modes it is defined for
             */
            step_sizes: string[];
            /**
             * Text
             * @description one line for people choosing it
             */
            text: string;
            /**
             * Traces
             * @description learns with eligibility traces (lambda > 0); false: lambda 0 only (a demon's lambda > 0 is a 422, and one that leaves lambda out learns with 0 whatever [learning] says)
             */
            traces: boolean;
        };
        /**
         * LearningSpec
         * @description Defaults for demons that do not set their own, chosen by `studies/stepsizes.toml` (see README).
         */
        LearningSpec: {
            /**
             * Alpha
             * @default 0.03
             */
            alpha: number;
            /**
             * Alpha W
             * @default 0.0001
             */
            alpha_w: number;
            /**
             * Autostep Tau
             * @description autostep's time scale tau of its normaliser v (Mahmood et al. 2012: 1e4)
             * @default 10000
             */
            autostep_tau: number;
            /**
             * Dtype
             * @description the numbers of the weights, secondary weights, traces and per-weight step sizes: float32 halves their memory and the bytes a step moves (sums are still taken in float64)
             * @default float64
             * @enum {string}
             */
            dtype: "float64" | "float32";
            /**
             * Lambda
             * @default 0.9
             */
            lambda: number;
            /**
             * Meta Step
             * @description autostep's mu and tidbd's theta (meta step size)
             * @default 0.01
             */
            meta_step: number;
            /**
             * Step Size
             * @description the step-size mode of demons that set none; an adaptive mode applies only to the learners it is defined for (td), the others keep constant step sizes
             * @default constant
             * @enum {string}
             */
            step_size: "constant" | "autostep" | "tidbd";
        };
        /** MaxExpr */
        "MaxExpr-Input": {
            /** Max */
            max: (number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Input"] | components["schemas"]["MulExpr-Input"] | components["schemas"]["MinExpr-Input"] | components["schemas"]["MaxExpr-Input"] | components["schemas"]["IfExpr-Input"])[];
        };
        /** MaxExpr */
        "MaxExpr-Output": {
            /** Max */
            max: (number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Output"] | components["schemas"]["MulExpr-Output"] | components["schemas"]["MinExpr-Output"] | components["schemas"]["MaxExpr-Output"] | components["schemas"]["IfExpr-Output"])[];
        };
        /**
         * MeOut
         * @description Who the request acts as, so that the dashboard shows only the controls that role may use.
         */
        MeOut: {
            /**
             * Id
             * @description the token's id ('teacher' for HORDE_TOKEN's holder), null when anonymous
             */
            id: string | null;
            /** Name */
            name: string | null;
            /**
             * Role
             * @description anonymous: no token on a server with HORDE_TOKEN (reads only)
             * @enum {string}
             */
            role: "teacher" | "student" | "viewer" | "anonymous";
            /**
             * Tokens
             * @description whether the server has roles (HORDE_TOKEN is set); without, all are teacher
             */
            tokens: boolean;
        };
        /**
         * MeasureSpec
         * @description What each run measures, at `checkpoints` evenly spaced points of its training (and before it).
         */
        MeasureSpec: {
            /**
             * Cap
             * @description rollout length limit
             * @default 10000
             */
            cap: number;
            /**
             * Checkpoints
             * @default 10
             */
            checkpoints: number;
            /**
             * Demons
             * @description which demons (default: every prediction demon)
             */
            demons?: string[] | null;
            /**
             * Episodes
             * @description training episodes per run (default: the base protocol's)
             */
            episodes?: number | null;
            /**
             * Rollouts
             * @description Monte-Carlo rollouts per checkpoint where no exact answer exists
             * @default 300
             */
            rollouts: number;
            /**
             * Weighting
             * @description worlds with known transitions (the chains, Baird's star): the RMS error over the states weighted by the behaviour's distribution (the book's VE) or every state alike (its 19-state walk figures)
             * @default on-policy
             * @enum {string}
             */
            weighting: "on-policy" | "uniform";
        };
        /** MinExpr */
        "MinExpr-Input": {
            /** Min */
            min: (number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Input"] | components["schemas"]["MulExpr-Input"] | components["schemas"]["MinExpr-Input"] | components["schemas"]["MaxExpr-Input"] | components["schemas"]["IfExpr-Input"])[];
        };
        /** MinExpr */
        "MinExpr-Output": {
            /** Min */
            min: (number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Output"] | components["schemas"]["MulExpr-Output"] | components["schemas"]["MinExpr-Output"] | components["schemas"]["MaxExpr-Output"] | components["schemas"]["IfExpr-Output"])[];
        };
        /** MulExpr */
        "MulExpr-Input": {
            /** Mul */
            mul: (number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Input"] | components["schemas"]["MulExpr-Input"] | components["schemas"]["MinExpr-Input"] | components["schemas"]["MaxExpr-Input"] | components["schemas"]["IfExpr-Input"])[];
        };
        /** MulExpr */
        "MulExpr-Output": {
            /** Mul */
            mul: (number | components["schemas"]["SensorExpr"] | components["schemas"]["PredictionExpr"] | components["schemas"]["AddExpr-Output"] | components["schemas"]["MulExpr-Output"] | components["schemas"]["MinExpr-Output"] | components["schemas"]["MaxExpr-Output"] | components["schemas"]["IfExpr-Output"])[];
        };
        /** ParameterOut */
        ParameterOut: {
            /** Default */
            default: number;
            /** High */
            high: number;
            /** Low */
            low: number;
            /** Name */
            name: string;
            /** Text */
            text: string;
        };
        /** PhasePlaneOut */
        PhasePlaneOut: {
            /** Demon */
            demon: string;
            /**
             * Trail
             * @description the recent (x, y) readings, oldest first
             */
            trail: number[][];
            /**
             * Values
             * @description [y cell][x cell] the demon's prediction (null: diverged)
             */
            values: (number | null)[][];
            x: components["schemas"]["AxisOut"];
            y: components["schemas"]["AxisOut"];
        };
        /**
         * PolicySpec
         * @description A target policy. Shorthands: "uniform", "greedy", "softmax", {of = "demon"}.
         */
        PolicySpec: {
            /**
             * Actions
             * @description sign: [action where negative, action where >= 0]
             */
            actions?: number[] | null;
            /**
             * Demon
             * @description of: the demon whose policy this follows
             */
            demon?: string | null;
            /**
             * Epsilon
             * @default 0.1
             */
            epsilon: number;
            /**
             * Kind
             * @default uniform
             * @enum {string}
             */
            kind: "uniform" | "fixed" | "greedy" | "softmax" | "epsilon_greedy" | "of" | "sign";
            /**
             * Probabilities
             * @description fixed: one per action of the world ([up, down, left, right] in the grid world)
             */
            probabilities?: number[] | null;
            /**
             * Sensor
             * @description sign: the sensor whose sign chooses the action
             */
            sensor?: string | null;
            /**
             * Temperature
             * @default 1
             */
            temperature: number;
        };
        /** PredictionExpr */
        PredictionExpr: {
            /**
             * Prediction
             * @description another demon's current prediction
             */
            prediction: string;
        };
        /**
         * ProtocolOut
         * @description A protocol job: a scenario's trials x episodes, truth and test runs, in the background.
         */
        ProtocolOut: {
            /**
             * Created At
             * Format: date-time
             */
            created_at: string;
            /** Episodes */
            episodes: number;
            /** Episodes Done */
            episodes_done: number;
            /** Episodes Total */
            episodes_total: number;
            /** Error */
            error: string;
            /** Finished At */
            finished_at: string | null;
            /** Id */
            id: string;
            /** Max Steps */
            max_steps: number;
            /** Name */
            name: string | null;
            /**
             * Owner
             * @description who started it: 'teacher', or the name of the student's token
             */
            owner: string;
            /** Results */
            results: components["schemas"]["DemonResultOut"][] | null;
            /** Rollouts */
            rollouts: number;
            /**
             * Seconds
             * @description learning and evaluation time, once finished
             */
            seconds: number | null;
            /** Seed */
            seed: number;
            /**
             * Status
             * @description interrupted: the server stopped (or died) while it ran; `error` says how far it got
             * @enum {string}
             */
            status: "running" | "finished" | "failed" | "cancelled" | "interrupted";
            /** Steps */
            steps: number | null;
            thesis_counts: components["schemas"]["CountsOut"] | null;
            /** Trials */
            trials: number;
        };
        /** ProtocolSpec */
        ProtocolSpec: {
            /**
             * Episodes
             * @default 1000
             */
            episodes: number;
            evaluation?: components["schemas"]["EvaluationSpec"];
            stop?: components["schemas"]["StopRule"] | null;
            test?: components["schemas"]["TestSpec"] | null;
            /**
             * Trials
             * @default 1
             */
            trials: number;
        };
        /**
         * RecordIn
         * @description One time step: what the sensors read, the action then taken, and (optionally) b(. | s).
         */
        RecordIn: {
            /**
             * Action
             * @description the action taken after this observation, in [0, actions)
             */
            action: number;
            /**
             * Behaviour Probabilities
             * @description b(a | s) of every action (uniform when left out)
             */
            behaviour_probabilities?: number[] | null;
            /**
             * Observation
             * @description one reading per sensor, in the world's order
             */
            observation: number[];
        };
        /** RecordsIn */
        RecordsIn: {
            /** Records */
            records: components["schemas"]["RecordIn"][];
        };
        /** Region */
        Region: {
            /**
             * Colors
             * @description indicator regions only
             */
            colors?: components["schemas"]["Color"][] | null;
            /**
             * Kind
             * @enum {string}
             */
            kind: "obstacle" | "terminal" | "zone" | "indicator";
            /** Name */
            name: string;
            /**
             * Rect
             * @description [x0, y0, x1, y1]
             */
            rect: number[];
            /**
             * Reward
             * @description terminal regions only: a number or a reward per indicator colour
             */
            reward?: number | components["schemas"]["IndicatorReward"] | null;
        };
        /**
         * RngState
         * @description The state of a PCG64 generator; the two 128-bit numbers are decimal strings.
         */
        RngState: {
            /**
             * Bit Generator
             * @default PCG64
             * @constant
             */
            bit_generator: "PCG64";
            /** Has Uint32 */
            has_uint32: number;
            /** Inc */
            inc: string;
            /** State */
            state: string;
            /** Uinteger */
            uinteger: number;
        };
        /** RunBriefOut */
        RunBriefOut: {
            /**
             * Created At
             * Format: date-time
             */
            created_at: string;
            /** Demons */
            demons: string[];
            /**
             * Episode
             * @description episodes completed
             */
            episode: number;
            evaluation: components["schemas"]["EvaluationSupportOut"];
            /** Hz */
            hz: number | null;
            /** Id */
            id: string;
            /** Message */
            message: string;
            /** Name */
            name: string | null;
            /**
             * Owner
             * @description who created it: 'teacher', or the name of the student's token
             */
            owner: string;
            /**
             * Status
             * @enum {string}
             */
            status: "created" | "running" | "paused" | "finished" | "failed";
            /**
             * Step
             * @description steps taken in all
             */
            step: number;
            /**
             * Updated At
             * Format: date-time
             */
            updated_at: string;
            worker: components["schemas"]["WorkerOut"];
        };
        /**
         * RunCardOut
         * @description A run as the Class tab's card shows it.
         */
        RunCardOut: {
            /** Episode */
            episode: number;
            /** Id */
            id: string;
            /**
             * Name
             * @description the run spec's name (its scenario's, unless renamed)
             */
            name: string | null;
            /** Owner */
            owner: string;
            sparkline: components["schemas"]["SparklineOut"];
            /**
             * Status
             * @enum {string}
             */
            status: "created" | "running" | "paused" | "finished" | "failed";
            /** Step */
            step: number;
            /**
             * Updated At
             * Format: date-time
             */
            updated_at: string;
        };
        /** RunOut */
        RunOut: {
            /**
             * Created At
             * Format: date-time
             */
            created_at: string;
            /** Demons */
            demons: string[];
            /**
             * Episode
             * @description episodes completed
             */
            episode: number;
            evaluation: components["schemas"]["EvaluationSupportOut"];
            /** Hz */
            hz: number | null;
            /** Id */
            id: string;
            /** Message */
            message: string;
            /** Name */
            name: string | null;
            /**
             * Owner
             * @description who created it: 'teacher', or the name of the student's token
             */
            owner: string;
            spec: components["schemas"]["RunSpec-Output"];
            /**
             * Status
             * @enum {string}
             */
            status: "created" | "running" | "paused" | "finished" | "failed";
            /**
             * Step
             * @description steps taken in all
             */
            step: number;
            summary: components["schemas"]["SummaryOut"] | null;
            /**
             * Updated At
             * Format: date-time
             */
            updated_at: string;
            worker: components["schemas"]["WorkerOut"];
        };
        /**
         * RunPatchIn
         * @description Change a run's speed and/or behaviour policy; a field left out stays as it is.
         */
        RunPatchIn: {
            behaviour?: components["schemas"]["BehaviourSpec"] | null;
            /** Hz */
            hz?: number | null;
        };
        /** RunSpec */
        "RunSpec-Input": {
            behaviour?: components["schemas"]["BehaviourSpec"];
            /** Demons */
            demons?: components["schemas"]["DemonSpec-Input"][];
            /**
             * Description
             * @default
             */
            description: string;
            /**
             * Families
             * @description demon families, expanded into `demons` when the spec is read (and then empty)
             */
            families?: components["schemas"]["DemonFamily"][];
            features?: components["schemas"]["FeatureSpec"];
            learning?: components["schemas"]["LearningSpec"];
            /** Name */
            name?: string | null;
            protocol?: components["schemas"]["ProtocolSpec"];
            /**
             * Seed
             * @default 0
             */
            seed: number;
            thesis?: components["schemas"]["ThesisResults"];
            /** World */
            world?: components["schemas"]["WorldSpec"] | components["schemas"]["GymnasiumWorldSpec"] | components["schemas"]["StreamWorldSpec"];
        };
        /** RunSpec */
        "RunSpec-Output": {
            behaviour?: components["schemas"]["BehaviourSpec"];
            /** Demons */
            demons?: components["schemas"]["DemonSpec-Output"][];
            /**
             * Description
             * @default
             */
            description: string;
            /**
             * Families
             * @description demon families, expanded into `demons` when the spec is read (and then empty)
             */
            families?: components["schemas"]["DemonFamily"][];
            features?: components["schemas"]["FeatureSpec"];
            learning?: components["schemas"]["LearningSpec"];
            /** Name */
            name?: string | null;
            protocol?: components["schemas"]["ProtocolSpec"];
            /**
             * Seed
             * @default 0
             */
            seed: number;
            thesis?: components["schemas"]["ThesisResults"];
            /** World */
            world?: components["schemas"]["WorldSpec"] | components["schemas"]["GymnasiumWorldSpec"] | components["schemas"]["StreamWorldSpec"];
        };
        /** @description A message of WS /api/runs/{id}/stream: the run's state, with the events since the previous message (at most about 30 a second). */
        RunStreamMessage: components["schemas"]["StateOut"];
        /**
         * RunTemplateIn
         * @description A run from a scenario and/or a stored world, with overrides of any top-level RunSpec field.
         *
         *     Objects (world, features, behaviour, learning, protocol, thesis) are merged key by key into the
         *     scenario's, recursively; plain values (name, description, seed) replace it; `demons` replaces the
         *     scenario's demons (its families already expanded into them); `families` are expanded into more demons
         *     beside those (kept or replaced), so `{scenario, families}` adds a family to a scenario. Without a
         *     scenario the base is the default RunSpec. `world` names a stored world, or is an object merged into
         *     the scenario's world.
         */
        RunTemplateIn: {
            /** Behaviour */
            behaviour?: {
                [key: string]: unknown;
            } | string | null;
            /** Demons */
            demons?: {
                [key: string]: unknown;
            }[] | null;
            /** Description */
            description?: string | null;
            /** Families */
            families?: {
                [key: string]: unknown;
            }[] | null;
            /** Features */
            features?: {
                [key: string]: unknown;
            } | null;
            /** Learning */
            learning?: {
                [key: string]: unknown;
            } | null;
            /** Name */
            name?: string | null;
            /** Protocol */
            protocol?: {
                [key: string]: unknown;
            } | null;
            /**
             * Scenario
             * @description a scenario name (GET /api/scenarios)
             */
            scenario?: string | null;
            /** Seed */
            seed?: number | null;
            /** Thesis */
            thesis?: {
                [key: string]: unknown;
            } | null;
            /**
             * World
             * @description a stored world's name, or overrides
             */
            world?: string | {
                [key: string]: unknown;
            } | null;
        };
        /**
         * SampleSpec
         * @description Every configuration of the grid, or `size` of them drawn at random (without repeats, seeded).
         */
        SampleSpec: {
            /**
             * Kind
             * @default grid
             * @enum {string}
             */
            kind: "grid" | "random";
            /**
             * Seed
             * @default 0
             */
            seed: number;
            /**
             * Size
             * @description random: how many
             */
            size?: number | null;
        };
        /** ScenarioOut */
        ScenarioOut: {
            /** Description */
            description: string;
            /**
             * Error
             * @description why the file does not load, if it does not
             */
            error?: string | null;
            /** Name */
            name: string;
            /**
             * Watch Hz
             * @description the speed to watch it at live, steps per second (its `[watch]` table); null: full
             */
            watch_hz?: number | null;
            /**
             * Watch Note
             * @description why that speed, and what to watch for
             * @default
             */
            watch_note: string;
        };
        /** SensorExpr */
        SensorExpr: {
            /**
             * Sensor
             * @description a sensor name, e.g. in:goal
             */
            sensor: string;
        };
        /**
         * SensorRange
         * @description One sensor of a non-grid world: its name and, where known, the range its readings stay in.
         */
        SensorRange: {
            /**
             * High
             * @description the highest reading
             */
            high?: number | null;
            /**
             * Low
             * @description the lowest reading (a bound or a documented range)
             */
            low?: number | null;
            /** Name */
            name: string;
        };
        /**
         * Snapshot
         * @description A run at one step, complete enough to resume it exactly.
         */
        "Snapshot-Input": {
            /** Episode */
            episode: number;
            /** Episode Return */
            episode_return: number;
            /**
             * Format
             * @default horde-snapshot/1
             * @constant
             */
            format: "horde-snapshot/1";
            /** Horde */
            horde: {
                [key: string]: components["schemas"]["EncodedArray"] | number;
            };
            /** Hz */
            hz?: number | null;
            /** Last Return */
            last_return: number;
            /**
             * Online
             * @description the true online, emphatic and adaptive learners' state beyond the weights and traces: per-weight step sizes (autostep, tidbd) and their normalisers, v_old, followon traces; absent in older snapshots, which restore these at their start values
             */
            online?: {
                [key: string]: components["schemas"]["EncodedArray"];
            } | null;
            rng: components["schemas"]["RngState"];
            spec: components["schemas"]["RunSpec-Input"];
            /**
             * Status
             * @enum {string}
             */
            status: "created" | "running" | "paused" | "finished" | "failed";
            /**
             * Stop Reference
             * @description weights at the stopping rule's last check, one array per demon group
             */
            stop_reference?: components["schemas"]["EncodedArray"][] | null;
            /** Total Steps */
            total_steps: number;
            /** World */
            world: {
                [key: string]: components["schemas"]["EncodedArray"];
            };
        };
        /**
         * Snapshot
         * @description A run at one step, complete enough to resume it exactly.
         */
        "Snapshot-Output": {
            /** Episode */
            episode: number;
            /** Episode Return */
            episode_return: number;
            /**
             * Format
             * @default horde-snapshot/1
             * @constant
             */
            format: "horde-snapshot/1";
            /** Horde */
            horde: {
                [key: string]: components["schemas"]["EncodedArray"] | number;
            };
            /** Hz */
            hz?: number | null;
            /** Last Return */
            last_return: number;
            /**
             * Online
             * @description the true online, emphatic and adaptive learners' state beyond the weights and traces: per-weight step sizes (autostep, tidbd) and their normalisers, v_old, followon traces; absent in older snapshots, which restore these at their start values
             */
            online?: {
                [key: string]: components["schemas"]["EncodedArray"];
            } | null;
            rng: components["schemas"]["RngState"];
            spec: components["schemas"]["RunSpec-Output"];
            /**
             * Status
             * @enum {string}
             */
            status: "created" | "running" | "paused" | "finished" | "failed";
            /**
             * Stop Reference
             * @description weights at the stopping rule's last check, one array per demon group
             */
            stop_reference?: components["schemas"]["EncodedArray"][] | null;
            /** Total Steps */
            total_steps: number;
            /** World */
            world: {
                [key: string]: components["schemas"]["EncodedArray"];
            };
        };
        /**
         * SparklineOut
         * @description A run's first demons' predictions over its recent history, thinned to a few dozen points.
         */
        SparklineOut: {
            /**
             * Series
             * @description demon name -> prediction at each of `steps`
             */
            series: {
                [key: string]: (number | null)[];
            };
            /** Steps */
            steps: number[];
        };
        /**
         * StateOut
         * @description The live state of a run; also the message of its WebSocket stream.
         */
        StateOut: {
            agent: components["schemas"]["AgentOut"];
            /**
             * Demon Total
             * @description the run's demons; a stream message carries at most 200 of them, the next ones in turn
             * @default 0
             */
            demon_total: number;
            /** Episode */
            episode: number;
            /** Episode Return */
            episode_return: number | null;
            /** Episode Step */
            episode_step: number;
            /**
             * Events
             * @description recent events (a stream message: those since the last message)
             */
            events: components["schemas"]["EventOut"][];
            /** Hz */
            hz: number | null;
            /** Last Return */
            last_return: number | null;
            /** Message */
            message: string;
            /** Metrics */
            metrics: {
                [key: string]: components["schemas"]["DemonMetricsOut"];
            };
            /**
             * Predictions
             * @description each demon's prediction at the agent's state (a stream message of a large Horde: some of them)
             */
            predictions: {
                [key: string]: number | null;
            };
            /** Run */
            run: string;
            /**
             * Sensors
             * @description a Gymnasium run's sensors at the agent's state (its `agent` is then the first two of them)
             */
            sensors?: {
                [key: string]: number | null;
            } | null;
            /**
             * Status
             * @enum {string}
             */
            status: "created" | "running" | "paused" | "finished" | "failed";
            /** Step */
            step: number;
            /**
             * Type
             * @default state
             * @constant
             */
            type: "state";
        };
        /** StepIn */
        StepIn: {
            /**
             * Steps
             * @default 1
             */
            steps: number;
        };
        /**
         * StopRule
         * @description Stop a trial early once no weight moved by more than `tolerance` over `window` episodes.
         */
        StopRule: {
            /**
             * Tolerance
             * @default 0.001
             */
            tolerance: number;
            /**
             * Window
             * @default 100
             */
            window: number;
        };
        /**
         * StreamClose
         * @description How the server closes a WebSocket stream: 1000 NORMAL: the stream is over (a study stopped); 1001 GOING_AWAY: the server is stopping; 1008 ORIGIN_REFUSED: a page of another site may not open the stream; 1013 TOO_SLOW: the client fell too far behind, or a send timed out ('try again later'); 4401 UNAUTHORIZED: the server requires a token (pushing records to a stream run), or the token given is not the server's or was revoked; 4403 FORBIDDEN: the token's role may not do this (a viewer's, or a student's on another's stream run); 4404 NOT_FOUND: no such run (or study, or stream run); 4410 RUN_DELETED: the run (or stream run) was deleted while streamed
         * @enum {integer}
         */
        StreamClose: 1000 | 1001 | 1008 | 1013 | 4401 | 4403 | 4404 | 4410;
        /** StreamHistoryOut */
        StreamHistoryOut: {
            /**
             * Predictions
             * @description demon -> its prediction on observing each record (null: not a finite number)
             */
            predictions: {
                [key: string]: (number | null)[];
            };
            /**
             * Records
             * @description each row's record number in the stream (0 = the first ever sent)
             */
            records: number[];
            /**
             * Returns
             * @description demon -> the discounted return that followed each record, computed afterwards from the records after it (null where the stream has not gone far enough yet, or a refused record broke it; the behaviour's return, so the demon's answer only for on-policy questions); null for a demon whose question reads other demons' predictions
             */
            returns: {
                [key: string]: (number | null)[] | null;
            };
            /**
             * Sensors
             * @description sensor -> its reading at each record
             */
            sensors: {
                [key: string]: number[];
            };
        };
        /** StreamOut */
        StreamOut: {
            /** Actions */
            actions: number;
            /** Demons */
            demons: string[];
            /** Id */
            id: string;
            /**
             * Learned
             * @description good records taken in (the first observed, every later one learned)
             */
            learned: number;
            /**
             * Name
             * @description the run spec's name
             * @default
             */
            name: string;
            /**
             * Owner
             * @description who started it: 'teacher', or the name of the student's token
             */
            owner: string;
            /**
             * Predictions
             * @description each demon's prediction at the last observation
             */
            predictions: {
                [key: string]: number;
            };
            /**
             * Received
             * @description records received, good or refused
             */
            received: number;
            /** Sensors */
            sensors: string[];
        };
        /**
         * StreamSnapshot
         * @description A stream run's learner at one record, complete enough to go on exactly.
         */
        "StreamSnapshot-Input": {
            /**
             * Format
             * @default horde-stream-snapshot/1
             * @constant
             */
            format: "horde-stream-snapshot/1";
            /** Horde */
            horde: {
                [key: string]: components["schemas"]["EncodedArray"] | number;
            };
            /** Learned */
            learned: number;
            /**
             * Pending Action
             * @description a_t of the last good record (null: none)
             */
            pending_action?: number | null;
            /**
             * Pending Probability
             * @description b(a_t | s_t) there
             */
            pending_probability?: number | null;
            /** Received */
            received: number;
            /** Refused */
            refused: number;
            /** @description [S] the sensors of the last observation */
            sensors: components["schemas"]["EncodedArray"];
            spec: components["schemas"]["RunSpec-Input"];
        };
        /**
         * StreamSnapshot
         * @description A stream run's learner at one record, complete enough to go on exactly.
         */
        "StreamSnapshot-Output": {
            /**
             * Format
             * @default horde-stream-snapshot/1
             * @constant
             */
            format: "horde-stream-snapshot/1";
            /** Horde */
            horde: {
                [key: string]: components["schemas"]["EncodedArray"] | number;
            };
            /** Learned */
            learned: number;
            /**
             * Pending Action
             * @description a_t of the last good record (null: none)
             */
            pending_action?: number | null;
            /**
             * Pending Probability
             * @description b(a_t | s_t) there
             */
            pending_probability?: number | null;
            /** Received */
            received: number;
            /** Refused */
            refused: number;
            /** @description [S] the sensors of the last observation */
            sensors: components["schemas"]["EncodedArray"];
            spec: components["schemas"]["RunSpec-Output"];
        };
        /**
         * StreamWorldSpec
         * @description Observations a client pushes (a robot, a recorded log): the sensors it sends and its number of actions.
         *
         *     A record is (observation: one reading per sensor, in this order; the action taken; optionally the
         *     behaviour's probabilities of every action, uniform when left out). The stream is one continuing
         *     episode: nothing terminates it.
         */
        StreamWorldSpec: {
            /**
             * Actions
             * @description the number of actions a record's action is one of
             */
            actions: number;
            /**
             * Kind
             * @constant
             */
            kind: "stream";
            /** Name */
            name?: string | null;
            /** Sensors */
            sensors: components["schemas"]["SensorRange"][];
        };
        /**
         * StudyConfigOut
         * @description One configuration over its finished runs.
         */
        StudyConfigOut: {
            /** Auc */
            auc: number | null;
            /** Auc High */
            auc_high: number | null;
            /** Auc Low */
            auc_low: number | null;
            /** Axes */
            axes: {
                [key: string]: number | string | boolean;
            };
            /**
             * Best
             * @description the lowest final relative error of the study (never a diverged configuration)
             */
            best: boolean;
            /** Ci High */
            ci_high: number | null;
            /** Ci Low */
            ci_low: number | null;
            /** @description relative error per checkpoint */
            curve: components["schemas"]["BandOut"];
            /** Demons */
            demons: {
                [key: string]: components["schemas"]["StudyDemonOut"];
            };
            /**
             * Diverged
             * @description a run diverged: its final relative error or AUC non-finite or above 1e6, or a measured demon frozen by the engine as diverged; its numbers are then not a fit
             */
            diverged: boolean;
            /**
             * Episodes
             * @description training episodes at each checkpoint
             */
            episodes: number[];
            /**
             * Error
             * @description final relative error: error / scale, mean over the demons
             */
            error: number | null;
            /** Index */
            index: number;
            /** @description control protocols: the share of test runs ending in a positive terminal */
            positive?: components["schemas"]["BandOut"] | null;
            /** @description mean return of the episodes before each checkpoint */
            returns: components["schemas"]["BandOut"];
            /** Runs */
            runs: number;
            /**
             * Truth
             * @enum {string}
             */
            truth: "exact" | "monte_carlo";
        };
        /**
         * StudyDemonOut
         * @description One demon of one configuration: final error (the question's own units), its interval, its curve.
         */
        StudyDemonOut: {
            /**
             * Auc
             * @description mean error over the checkpoints after episode 0
             */
            auc: number | null;
            /** Ci High */
            ci_high: number | null;
            /** Ci Low */
            ci_low: number | null;
            curve: components["schemas"]["BandOut"];
            /** Error */
            error: number | null;
            rupee: components["schemas"]["BandOut"];
        };
        /**
         * StudyOut
         * @description A study and how far it has got.
         */
        StudyOut: {
            /** Axes */
            axes: components["schemas"]["AxisSpec"][];
            /** Configurations */
            configurations: number;
            /**
             * Created At
             * Format: date-time
             */
            created_at: string;
            /**
             * Episodes
             * @description training episodes per run
             */
            episodes: number;
            /** Id */
            id: string;
            /** Message */
            message: string;
            /** Name */
            name: string | null;
            /**
             * Owner
             * @description who started it: 'teacher', or the name of the student's token
             */
            owner: string;
            /**
             * Runs
             * @description runs per configuration
             */
            runs: number;
            /**
             * Scenario
             * @description the base run spec's name
             */
            scenario: string | null;
            /**
             * Seconds Left
             * @description estimated from the pace so far (running studies only)
             */
            seconds_left: number | null;
            /**
             * Status
             * @enum {string}
             */
            status: "created" | "running" | "finished" | "failed" | "cancelled" | "interrupted";
            /**
             * Tasks
             * @description configurations x runs
             */
            tasks: number;
            /** Tasks Done */
            tasks_done: number;
            /**
             * Updated At
             * Format: date-time
             */
            updated_at: string;
        };
        /**
         * StudyResultsOut
         * @description A study with every configuration that has a finished run.
         */
        StudyResultsOut: {
            /** Axes */
            axes: components["schemas"]["AxisSpec"][];
            /** Configurations */
            configurations: number;
            /**
             * Created At
             * Format: date-time
             */
            created_at: string;
            /**
             * Episodes
             * @description training episodes per run
             */
            episodes: number;
            /** Id */
            id: string;
            /** Message */
            message: string;
            /** Name */
            name: string | null;
            /**
             * Owner
             * @description who started it: 'teacher', or the name of the student's token
             */
            owner: string;
            /** Results */
            results: components["schemas"]["StudyConfigOut"][];
            /**
             * Runs
             * @description runs per configuration
             */
            runs: number;
            /**
             * Scenario
             * @description the base run spec's name
             */
            scenario: string | null;
            /**
             * Seconds Left
             * @description estimated from the pace so far (running studies only)
             */
            seconds_left: number | null;
            /**
             * Status
             * @enum {string}
             */
            status: "created" | "running" | "finished" | "failed" | "cancelled" | "interrupted";
            /**
             * Tasks
             * @description configurations x runs
             */
            tasks: number;
            /** Tasks Done */
            tasks_done: number;
            /**
             * Updated At
             * Format: date-time
             */
            updated_at: string;
            /**
             * Warnings
             * @description what the results will not show on their own (gtd learning as td at alpha_w = 0)
             */
            warnings: string[];
        };
        /**
         * StudySpec
         * @description A parameter study (DESIGN: studies/).
         */
        StudySpec: {
            /**
             * Axes
             * @description none: one configuration, the base, over `runs`
             */
            axes?: components["schemas"]["AxisSpec"][];
            /** @description the base run spec (or name a `scenario`) */
            base?: components["schemas"]["RunSpec-Input"] | null;
            /**
             * Caption
             * @description written under every figure: which figure, the set-up, what to see
             * @default
             */
            caption: string;
            /**
             * Description
             * @default
             */
            description: string;
            measure?: components["schemas"]["MeasureSpec"];
            /** Name */
            name?: string | null;
            /**
             * Runs
             * @description independent runs per configuration
             * @default 5
             */
            runs: number;
            sample?: components["schemas"]["SampleSpec"];
            /**
             * Scenario
             * @description the base scenario's name (or give `base`)
             */
            scenario?: string | null;
        };
        /** @description A message of WS /api/studies/{id}/stream: the study, twice a second while it runs, and once when it stops. */
        StudyStreamMessage: components["schemas"]["StudyOut"];
        /**
         * SummaryOut
         * @description How a finished run ended; predictions are read at the world's start point.
         */
        SummaryOut: {
            /** Episodes */
            episodes: number;
            /** Last Return */
            last_return: number | null;
            /** Predictions */
            predictions: {
                [key: string]: number | null;
            };
            /** Rupee */
            rupee: {
                [key: string]: number | null;
            };
            /** Steps */
            steps: number;
            /** Stopped Early */
            stopped_early: boolean;
            /** Ude */
            ude: {
                [key: string]: number | null;
            };
        };
        /**
         * TestSpec
         * @description Test runs after each trial: the behaviour below, no learning except reset-each-episode demons.
         */
        TestSpec: {
            behaviour: components["schemas"]["BehaviourSpec"];
            /**
             * Runs
             * @default 100
             */
            runs: number;
        };
        /**
         * ThesisResults
         * @description The thesis's numbers, shown beside ours.
         */
        ThesisResults: {
            counts?: components["schemas"]["Counts"] | null;
            /** Predictions */
            predictions?: {
                [key: string]: number;
            };
        };
        /**
         * TiledSensor
         * @description One sensor that features read (tiled by `sensors`, the input of a basis): its readings in [low, high] are
         *     scaled to [0, 1] (and clipped). A range left out is the world's (`horde.spec.run.check_world_fit` refuses a
         *     sensor without one).
         */
        TiledSensor: {
            /**
             * High
             * @description the highest reading resolved (default: the world's range)
             */
            high?: number | null;
            /**
             * Low
             * @description the lowest reading resolved (default: the world's range)
             */
            low?: number | null;
            /**
             * Sensor
             * @description a sensor name, e.g. in:zone3
             */
            sensor: string;
        };
        /**
         * TokenIn
         * @description A token to issue (POST /api/tokens, the teacher's).
         */
        TokenIn: {
            /**
             * Name
             * @description who holds it (a student's name): shown as the owner of what they make
             */
            name: string;
            /**
             * Role
             * @description student: creates runs, worlds, studies and changes only those; viewer: changes nothing
             * @enum {string}
             */
            role: "student" | "viewer";
        };
        /** TokenIssuedOut */
        TokenIssuedOut: {
            /**
             * Created At
             * Format: date-time
             */
            created_at: string;
            /**
             * Id
             * @description the token's id (DELETE /api/tokens/{id} revokes it); never the secret
             */
            id: string;
            /**
             * Link
             * @description an invitation: the dashboard's address carrying the token (?token=...)
             */
            link: string;
            /** Name */
            name: string;
            /**
             * Role
             * @enum {string}
             */
            role: "student" | "viewer";
            /**
             * Token
             * @description the secret, shown this once (the server keeps only its SHA-256)
             */
            token: string;
        };
        /** TokenOut */
        TokenOut: {
            /**
             * Created At
             * Format: date-time
             */
            created_at: string;
            /**
             * Id
             * @description the token's id (DELETE /api/tokens/{id} revokes it); never the secret
             */
            id: string;
            /** Name */
            name: string;
            /**
             * Role
             * @enum {string}
             */
            role: "student" | "viewer";
        };
        /** ValidationError */
        ValidationError: {
            /** Context */
            ctx?: Record<string, never>;
            /** Input */
            input?: unknown;
            /** Location */
            loc: (string | number)[];
            /** Message */
            msg: string;
            /** Error Type */
            type: string;
        };
        /**
         * ValuesOut
         * @description On the grid (`kind` "grid"): values[j][i] is the demon's prediction at (x[i], y[j]), the centres of an N x N
         *     grid. On a world of discrete states with known transitions (`kind` "states": the chains, Baird's star):
         *     values[0][i] is the prediction at state x[i] (y is empty, N the number of states), beside `exact` (the true
         *     values), `fixed_point` (the TD fixed point's values), and the errors over the states: `rmsve` and `rmspbe`
         *     weighted by the behaviour's distribution (`weighting`), `rms_error` every state alike (horde.worlds.state_values).
         */
        ValuesOut: {
            /** Demon */
            demon: string;
            /** Exact */
            exact?: number[] | null;
            /** Fixed Point */
            fixed_point?: number[] | null;
            /** Height */
            height: number;
            /**
             * Kind
             * @default grid
             * @enum {string}
             */
            kind: "grid" | "states";
            /** Max */
            max: number | null;
            /** Min */
            min: number | null;
            /** Resolution */
            resolution: number;
            /** Rms Error */
            rms_error?: number | null;
            /** Rmspbe */
            rmspbe?: number | null;
            /** Rmsve */
            rmsve?: number | null;
            /** Values */
            values: (number | null)[][];
            /** Weighting */
            weighting?: string | null;
            /** Width */
            width: number;
            /** X */
            x: number[];
            /** Y */
            y: number[];
        };
        /** ViewIn */
        ViewIn: {
            /**
             * Demons
             * @description the demons to label and chart (the first ones by default)
             */
            demons?: string[] | null;
            /**
             * Large
             * @description Large text: the view's labels and panel larger (for a projector); null: unchanged
             */
            large?: boolean | null;
            /**
             * Run
             * @description the run the tab's live view should show
             */
            run: string;
            /**
             * Viewer
             * @description a dashboard tab's own random key (8 to 64 letters, digits, - or _): the browsers that opened the view at GET /api/view?viewer=<key>'s url follow this tab's choice, no others
             */
            viewer: string;
        };
        /**
         * ViewOut
         * @description Whether the viser live view runs, where it listens, and which run it shows one dashboard tab.
         */
        ViewOut: {
            /**
             * Browsers
             * @description browsers connected to the live view now, each with its own view
             * @default 0
             */
            browsers: number;
            /**
             * Enabled
             * @description false when the server runs without the live view (`horde serve --no-view`)
             */
            enabled: boolean;
            /**
             * Frame Rate
             * @description frames drawn a second over the last 5 s (a frame draws every browser's view)
             * @default 0
             */
            frame_rate: number;
            /**
             * Run
             * @description the run shown to the browsers of `viewer`, if it chose one
             */
            run: string | null;
            /**
             * Url
             * @description the viser client's address (embed it in an iframe or open it); with `viewer`, the address whose browsers follow that tab's choice
             */
            url: string | null;
        };
        /**
         * WorkerOut
         * @description Where a run learns: a process of the server's machine, or a Ray actor on a node of its cluster.
         */
        WorkerOut: {
            /** Alive */
            alive: boolean;
            /**
             * Kind
             * @description none: the run has no worker (its worker died)
             * @enum {string}
             */
            kind: "process" | "ray" | "none";
            /**
             * Node
             * @description the Ray node the worker runs on (null for a process of this machine)
             */
            node: string | null;
            /**
             * Pid
             * @description the worker's process id, on its node
             */
            pid: number | null;
        };
        /**
         * WorldCreate
         * @description A world to store under its name (POST /api/worlds).
         */
        WorldCreate: {
            /**
             * Height
             * @default 500
             */
            height: number;
            /**
             * Max Steps
             * @default 100
             */
            max_steps: number;
            /** Name */
            name: string;
            /**
             * Noise
             * @description std of Gaussian noise added to every move
             * @default 0
             */
            noise: number;
            /** Regions */
            regions?: components["schemas"]["Region"][];
            /**
             * Slip
             * @description probability of a perpendicular move
             * @default 0
             */
            slip: number;
            /**
             * Start
             * @description a point [x, y] or a rectangle [x0, y0, x1, y1]
             */
            start?: number[];
            /**
             * Step
             * @default 100
             */
            step: number;
            /**
             * Transient Reward
             * @default -0.01
             */
            transient_reward: number;
            /**
             * Width
             * @default 500
             */
            width: number;
        };
        /** WorldOut */
        WorldOut: {
            /**
             * Created At
             * Format: date-time
             */
            created_at: string;
            /** Name */
            name: string;
            /**
             * Owner
             * @description who stored it: 'teacher', or the name of the student's token
             */
            owner: string;
            /**
             * Updated At
             * Format: date-time
             */
            updated_at: string;
            world: components["schemas"]["WorldSpec"];
        };
        /**
         * WorldSpec
         * @description A continuous rectangle [0, width) x [0, height) with rectangular regions.
         */
        WorldSpec: {
            /**
             * Height
             * @default 500
             */
            height: number;
            /**
             * Max Steps
             * @default 100
             */
            max_steps: number;
            /** Name */
            name?: string | null;
            /**
             * Noise
             * @description std of Gaussian noise added to every move
             * @default 0
             */
            noise: number;
            /** Regions */
            regions?: components["schemas"]["Region"][];
            /**
             * Slip
             * @description probability of a perpendicular move
             * @default 0
             */
            slip: number;
            /**
             * Start
             * @description a point [x, y] or a rectangle [x0, y0, x1, y1]
             */
            start?: number[];
            /**
             * Step
             * @default 100
             */
            step: number;
            /**
             * Transient Reward
             * @default -0.01
             */
            transient_reward: number;
            /**
             * Width
             * @default 500
             */
            width: number;
        };
    };
    responses: never;
    parameters: never;
    requestBodies: never;
    headers: never;
    pathItems: never;
}
export type $defs = Record<string, never>;
export interface operations {
    health_api_health_get: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HealthOut"];
                };
            };
        };
    };
    list_lab_api_lab_get: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["LabExperimentOut"][];
                };
            };
        };
    };
    prepare_api_lab__experiment_id__prepare_post: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the experiment's id */
                experiment_id: string;
            };
            cookie?: never;
        };
        requestBody: {
            content: {
                "application/json": components["schemas"]["LabSetupIn"];
            };
        };
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["LabPreparedOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    list_learners_api_learners_get: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["LearnerOut"][];
                };
            };
        };
    };
    who_am_i_api_me_get: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["MeOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    overview_api_overview_get: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["RunCardOut"][];
                };
            };
        };
    };
    list_protocols_api_protocols_get: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ProtocolOut"][];
                };
            };
        };
    };
    start_protocol_api_protocols_post: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody: {
            content: {
                "application/json": components["schemas"]["RunSpec-Input"] | components["schemas"]["RunTemplateIn"];
            };
        };
        responses: {
            /** @description Successful Response */
            202: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ProtocolOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Too many evaluations or protocols at once, or the run is busy */
            429: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    get_protocol_api_protocols__job_id__get: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the protocol job's id */
                job_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ProtocolOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    cancel_protocol_api_protocols__job_id__delete: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the protocol job's id */
                job_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ProtocolOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    export_protocol_api_protocols__job_id__export_get: {
        parameters: {
            query?: {
                /** @description csv or json */
                format?: string;
            };
            header?: never;
            path: {
                job_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description A file (Content-Disposition: attachment) */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": unknown;
                    "text/csv": string;
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    list_runs_api_runs_get: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["RunBriefOut"][];
                };
            };
        };
    };
    create_run_api_runs_post: {
        parameters: {
            query?: {
                /** @description steps per second; leave out for full speed */
                hz?: number | null;
                /** @description start running at once */
                start?: boolean;
            };
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody: {
            content: {
                "application/json": components["schemas"]["RunSpec-Input"] | components["schemas"]["RunTemplateIn"];
            };
        };
        responses: {
            /** @description Successful Response */
            201: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["RunOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Not saved: the store could not write (say, the disk is full); the detail says why and whether the change holds (a run's command) or was not made (a new run or world) */
            503: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    import_snapshot_api_runs_import_post: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody: {
            content: {
                "application/json": components["schemas"]["Snapshot-Input"];
            };
        };
        responses: {
            /** @description Successful Response */
            201: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["RunOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Not saved: the store could not write (say, the disk is full); the detail says why and whether the change holds (a run's command) or was not made (a new run or world) */
            503: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    get_run_api_runs__run_id__get: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["RunOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    delete_run_api_runs__run_id__delete: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            204: {
                headers: {
                    [name: string]: unknown;
                };
                content?: never;
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Too many evaluations or protocols at once, or the run is busy */
            429: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    patch_run_api_runs__run_id__patch: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody: {
            content: {
                "application/json": components["schemas"]["RunPatchIn"];
            };
        };
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["RunOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Not saved: the store could not write (say, the disk is full); the detail says why and whether the change holds (a run's command) or was not made (a new run or world) */
            503: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    list_demons_api_runs__run_id__demons_get: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["DemonOut"][];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    add_demon_api_runs__run_id__demons_post: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody: {
            content: {
                "application/json": components["schemas"]["DemonSpec-Input"];
            };
        };
        responses: {
            /** @description Successful Response */
            201: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["DemonOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Not saved: the store could not write (say, the disk is full); the detail says why and whether the change holds (a run's command) or was not made (a new run or world) */
            503: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    get_demon_api_runs__run_id__demons__name__get: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the demon's name */
                name: string;
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["DemonOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    remove_demon_api_runs__run_id__demons__name__delete: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the demon's name */
                name: string;
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            204: {
                headers: {
                    [name: string]: unknown;
                };
                content?: never;
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Not saved: the store could not write (say, the disk is full); the detail says why and whether the change holds (a run's command) or was not made (a new run or world) */
            503: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    get_history_api_runs__run_id__demons__name__history_get: {
        parameters: {
            query?: {
                /** @description the last rows only */
                limit?: number | null;
            };
            header?: never;
            path: {
                /** @description the demon's name */
                name: string;
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HistoryOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    get_values_api_runs__run_id__demons__name__values_get: {
        parameters: {
            query?: {
                resolution?: number;
            };
            header?: never;
            path: {
                /** @description the demon's name */
                name: string;
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ValuesOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    evaluate_api_runs__run_id__evaluate_post: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody: {
            content: {
                "application/json": components["schemas"]["EvaluateIn"];
            };
        };
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["EvaluationOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Too many evaluations or protocols at once, or the run is busy */
            429: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    evaluations_api_runs__run_id__evaluations_get: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["EvaluationOut"][];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    export_history_api_runs__run_id__export_history_get: {
        parameters: {
            query?: {
                /** @description csv or json */
                format?: string;
            };
            header?: never;
            path: {
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description A file (Content-Disposition: attachment) */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": unknown;
                    "text/csv": string;
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    export_spec_api_runs__run_id__export_spec_get: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description A TOML file */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": unknown;
                    "application/toml": string;
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    pause_run_api_runs__run_id__pause_post: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["RunOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Not saved: the store could not write (say, the disk is full); the detail says why and whether the change holds (a run's command) or was not made (a new run or world) */
            503: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    reset_run_api_runs__run_id__reset_post: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["RunOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Not saved: the store could not write (say, the disk is full); the detail says why and whether the change holds (a run's command) or was not made (a new run or world) */
            503: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    export_snapshot_api_runs__run_id__snapshot_get: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["Snapshot-Output"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    start_run_api_runs__run_id__start_post: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["RunOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Not saved: the store could not write (say, the disk is full); the detail says why and whether the change holds (a run's command) or was not made (a new run or world) */
            503: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    get_state_api_runs__run_id__state_get: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["StateOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    step_run_api_runs__run_id__step_post: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the run's id */
                run_id: string;
            };
            cookie?: never;
        };
        requestBody?: {
            content: {
                "application/json": components["schemas"]["StepIn"] | null;
            };
        };
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["StateOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Not saved: the store could not write (say, the disk is full); the detail says why and whether the change holds (a run's command) or was not made (a new run or world) */
            503: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    list_scenarios_api_scenarios_get: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ScenarioOut"][];
                };
            };
        };
    };
    get_scenario_api_scenarios__name__get: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                name: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["RunSpec-Output"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    list_streams_api_streams_get: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["StreamOut"][];
                };
            };
        };
    };
    create_stream_api_streams_post: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody: {
            content: {
                "application/json": components["schemas"]["RunSpec-Input"];
            };
        };
        responses: {
            /** @description Successful Response */
            201: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["StreamOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Too many evaluations or protocols at once, or the run is busy */
            429: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    import_stream_api_streams_import_post: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody: {
            content: {
                "application/json": components["schemas"]["StreamSnapshot-Input"];
            };
        };
        responses: {
            /** @description Successful Response */
            201: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["StreamOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Too many evaluations or protocols at once, or the run is busy */
            429: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    get_stream_api_streams__stream_id__get: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the stream run's id */
                stream_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["StreamOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    delete_stream_api_streams__stream_id__delete: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the stream run's id */
                stream_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            204: {
                headers: {
                    [name: string]: unknown;
                };
                content?: never;
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    get_stream_demons_api_streams__stream_id__demons_get: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the stream run's id */
                stream_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["DemonOut"][];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    get_stream_history_api_streams__stream_id__history_get: {
        parameters: {
            query?: {
                /** @description comma-separated (default: the first 4) */
                sensors?: string | null;
                /** @description comma-separated (default: the first 4) */
                demons?: string | null;
                /** @description records, at most */
                last?: number;
            };
            header?: never;
            path: {
                /** @description the stream run's id */
                stream_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["StreamHistoryOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    get_phase_plane_api_streams__stream_id__phase_plane_get: {
        parameters: {
            query: {
                demon: string;
                /** @description the sensor along x */
                x: string;
                /** @description the sensor along y */
                y: string;
                resolution?: number;
            };
            header?: never;
            path: {
                /** @description the stream run's id */
                stream_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["PhasePlaneOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    push_records_api_streams__stream_id__records_post: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the stream run's id */
                stream_id: string;
            };
            cookie?: never;
        };
        requestBody: {
            content: {
                "application/json": components["schemas"]["RecordsIn"];
            };
        };
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["StreamOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    get_stream_snapshot_api_streams__stream_id__snapshot_get: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the stream run's id */
                stream_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["StreamSnapshot-Output"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    list_studies_api_studies_get: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["StudyOut"][];
                };
            };
        };
    };
    start_study_api_studies_post: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody: {
            content: {
                "application/json": components["schemas"]["StudySpec"];
            };
        };
        responses: {
            /** @description Successful Response */
            202: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["StudyOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Too many evaluations or protocols at once, or the run is busy */
            429: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    get_study_api_studies__study_id__get: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the study's id */
                study_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["StudyResultsOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    cancel_study_api_studies__study_id__delete: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the study's id */
                study_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["StudyOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    export_study_api_studies__study_id__export_get: {
        parameters: {
            query?: {
                /** @description csv: results; curves: the learning curves (CSV) */
                format?: string;
            };
            header?: never;
            path: {
                /** @description the study's id */
                study_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description A file (Content-Disposition: attachment) */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": unknown;
                    "text/csv": string;
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    resume_study_api_studies__study_id__resume_post: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the study's id */
                study_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            202: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["StudyOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Too many evaluations or protocols at once, or the run is busy */
            429: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    list_tokens_api_tokens_get: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["TokenOut"][];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    issue_token_api_tokens_post: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody: {
            content: {
                "application/json": components["schemas"]["TokenIn"];
            };
        };
        responses: {
            /** @description Successful Response */
            201: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["TokenIssuedOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    revoke_token_api_tokens__token_id__delete: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the token's id */
                token_id: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["TokenOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    get_view_api_view_get: {
        parameters: {
            query?: {
                viewer?: string | null;
            };
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ViewOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    show_run_api_view_post: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody: {
            content: {
                "application/json": components["schemas"]["ViewIn"];
            };
        };
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ViewOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    list_worlds_api_worlds_get: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["WorldOut"][];
                };
            };
        };
    };
    create_world_api_worlds_post: {
        parameters: {
            query?: never;
            header?: never;
            path?: never;
            cookie?: never;
        };
        requestBody: {
            content: {
                "application/json": components["schemas"]["WorldCreate"];
            };
        };
        responses: {
            /** @description Successful Response */
            201: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["WorldOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Not saved: the store could not write (say, the disk is full); the detail says why and whether the change holds (a run's command) or was not made (a new run or world) */
            503: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    get_world_api_worlds__name__get: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the world's name */
                name: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["WorldOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
        };
    };
    put_world_api_worlds__name__put: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the world's name */
                name: string;
            };
            cookie?: never;
        };
        requestBody: {
            content: {
                "application/json": components["schemas"]["WorldSpec"];
            };
        };
        responses: {
            /** @description Successful Response */
            200: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["WorldOut"];
                };
            };
            /** @description Created */
            201: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["WorldOut"];
                };
            };
            /** @description The body cannot be parsed (not JSON, not UTF-8) */
            400: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The resource's state forbids this request */
            409: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The body is larger than the server accepts (HORDE_MAX_BODY) */
            413: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Not saved: the store could not write (say, the disk is full); the detail says why and whether the change holds (a run's command) or was not made (a new run or world) */
            503: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
    delete_world_api_worlds__name__delete: {
        parameters: {
            query?: never;
            header?: never;
            path: {
                /** @description the world's name */
                name: string;
            };
            cookie?: never;
        };
        requestBody?: never;
        responses: {
            /** @description Successful Response */
            204: {
                headers: {
                    [name: string]: unknown;
                };
                content?: never;
            };
            /** @description HORDE_TOKEN is set and the bearer token is missing, not this server's, or revoked */
            401: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description The token's role may not do this: a viewer changes nothing; a student changes only what they created (the detail names the owner); only the teacher manages tokens */
            403: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Unknown run, demon, world or scenario */
            404: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
            /** @description Validation Error */
            422: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["HTTPValidationError"];
                };
            };
            /** @description Not saved: the store could not write (say, the disk is full); the detail says why and whether the change holds (a run's command) or was not made (a new run or world) */
            503: {
                headers: {
                    [name: string]: unknown;
                };
                content: {
                    "application/json": components["schemas"]["ErrorOut"];
                };
            };
        };
    };
}
