"""wavesph sph_core: the 2D weakly-compressible SPH solver as a library.

    from sph_core.scene import Scene, load_scene, make_scene      # TOML / dict -> validated Scene
    from sph_core.simulation import Simulation, UnstableError
    sim = Simulation(load_scene("examples/scenes/dambreak_martin_moyce.toml"), run_dir="runs/db")
    sim.advance_to(0.5, progress=None)   # outputs on their cadence; UnstableError(step, t, cause)
    cp = sim.checkpoint(); sim.restore(cp)   # exact state copy
    sim.probe_values()                   # {"front_x": ..., "<point>_p": ..., "<gauge>_eta": ...}
    sim.close()

Modules: scene (config), geometry (particle layout), particles (SoA storage), state (the typed
containers the kernels take), neighbours (cell lists), kernels (Wendland C2), eos (Tait), wcsph
(the physical terms as jitted passes), open_boundary (the jitted open-end terms), step (the one
jitted time loop), open_ends (open ends as a value of the run), simulation (the run), probes,
output, progress (a terminal progress bar over a run). Named cases (dam break, flumes) live in
the `wavesph.cases` package; the commands in `wavesph.cli`.
"""
