"""Studies over many runs, each point an independent run on dask: the speed-accuracy sweep
(sweeps: `wavesph bench accuracy`), the stability suite (stability: `wavesph bench stability`)
and the planner fitted to the sweep (planning: `wavesph plan`, `wavesph run --wave`)."""
