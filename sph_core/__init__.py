"""wavesph sph_core: the weakly-compressible SPH solver (2D, and 3D with ``dim = 3``) as a library.

    from sph_core.scene import Scene, load_scene, make_scene      # TOML / dict -> validated Scene
    from sph_core.simulation import Simulation, UnstableError
    sim = Simulation(load_scene("examples/scenes/dambreak_martin_moyce.toml"), run_dir="runs/db")
    sim.advance_to(0.5, progress=None)   # outputs on their cadence; UnstableError(step, t, cause)
    cp = sim.checkpoint(); sim.restore(cp)   # exact state copy
    sim.probe_values()                   # {"front_x": ..., "<point>_p": ..., "<gauge>_eta": ...}
    sim.close()

Modules: scene (config), geometry (particle layout; geometry3d for 3D scenes), particles (SoA storage), state (the typed
containers the kernels take), neighbours (cell lists), pairs (the one neighbour walk), terms (the
per-pair terms), kernels (Wendland C2), eos (Tait), wcsph (the passes and integrators),
open_boundary (the jitted open-end terms), step (the one jitted time loop), open_ends (open ends
as a value of the run), simulation (the run), probes, output, progress (a terminal progress bar
over a run). Named cases (dam break, flumes) live in `wavesph.cases`; the commands in
`wavesph.cli`.

The compiled kernels are cached on disk (numba ``cache=True``) in a folder named by a hash of
this package's sources, under a lock that lets several processes compile and load at once, with
numba's threading layer started on import so no cached kernel finds it missing (``kernel_cache``).
"""

import numba

from .kernel_cache import kernel_cache_dir, launch_threading_layer, lock_cache_files

# before any submodule's @njit(cache=True) builds its cache locator
numba.config.CACHE_DIR = kernel_cache_dir()
lock_cache_files()
launch_threading_layer()   # before any cached kernel's first call (kernel_cache)
