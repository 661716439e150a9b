"""wavesph cases: named scenes and their reference comparisons, on top of the solver, the wave
models and the server (none of which imports this package).

Modules: dambreak (Martin & Moyce test problem), dambreak_demo (`wavesph demo --dambreak`),
wave_flume (theory-driven open flumes vs theory), wave_decay (the SPH wave's own loss),
wave_analysis (RMSE, reflection, group velocity of gauge records), coupled_flume (Boussinesq
far field + SPH beach, and its two references), demo_flume (`wavesph demo`), local_server (the server
in a thread for the last two).
"""
