"""wavesph server: HTTP run management + coupling doors (WebSocket and plain TCP) + run store.

    wavesph serve [--host 127.0.0.1] [--port 8765] [--tcp-port 8766] [--runs-dir runs]
                  [--max-runs 2] [--max-particles 2000000] [--token T]   (or WAVESPH_* env)

HTTP (OpenAPI docs at /docs):
    POST   /runs                    {scene, mode: coupled|standalone, coupling: {window_max, z_ref},
                                     source: {theory, H, T, ...} (standalone with open ends)}
                                    201; 400 not JSON, 413 > max_body, 422 names the field (every
                                    number finite, the cross-field rules of server/validation.py),
                                    415 not JSON/TOML Content-Type, 429 queue full
                                    (Retry-After), 507 the store cannot write
    GET    /runs                    every run, including those of earlier server processes
    GET    /runs/{id}               status, t, steps, particles, particle_steps_per_s,
                                    coupling_overhead_share, stability, last_gauges, scene_hash
    GET    /runs/{id}/scene         canonical scene bytes (protocol scene hash = their SHA-256)
    GET    /runs/{id}/gauges        ?format=csv|json
    GET    /runs/{id}/bodies        ?format=csv|json (rigid bodies of the scene; 404 without)
    GET    /runs/{id}/events        Server-Sent Events, one `progress` event per change
    DELETE /runs/{id}               cancel (data so far kept)
    POST   /runs/{id}/resume        a failed/cancelled coupled run continues from its saved state
                                    (409 if there is none, or it does not match its seal)
Coupling: WebSocket /runs/{id}/couple, or the TCP port; frames of protocol/PROTOCOL.md. A HELLO
reserves its run (even a queued one); WELCOME comes when the run is built and a stepping slot free.

Inside, top to bottom (pyproject's import-linter contract): cli; main; routers | tcp;
deps | theory_client; doors; run_manager | flume_engine; engine | store | transports; schemas;
theory_source | settings. The run manager gets the engine factory and the built-in source driver
injected, so it knows neither the solver nor the doors.

Python entry point: ``server.main.create_app(settings, engine_factory=flume_engine)``; the coupled
engine contract is ``server.engine.CouplingEngine`` (see docs/developer/architecture.md).
"""
