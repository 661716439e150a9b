"""wavesph cases: each a named scene and its reference comparison, on top of the solver, the
wave models and the server (none of which imports this package); `wavesph.studies` runs them
many times, the command line (`wavesph.cli`) once.

Modules: dambreak (Martin & Moyce test problem), dambreak_demo (`wavesph demo --dambreak`),
dambreak_obstacle (a dam break on a tall structure), wall_impact (Lobovsky's wall pressure),
wave_flume (theory-driven open flumes vs theory), wave_decay and standing_wave (the SPH wave's
own loss), particle_noise (its measure), coupled_flume (Boussinesq far field + SPH beach, and
its two references), demo_flume (`wavesph demo`), rigid_bodies, heave_potential and wedge_entry
(floating and moving bodies against theory), schemes (the scheme options the cases share).
Reference tables are in data/. Post-processing is `wavesph.analysis`; the in-process server the
coupled cases drive over its real sockets is `wavesph.local_server`.
"""
