"""The WCSPH step on an NVIDIA GPU (numba-cuda): see docs/developer/gpu.md.

Scope today: the kdk or symplectic_pc integrator, delta-SPH + Monaghan AV or Riemann SPH (with
or without MUSCL), Lo & Shao viscosity, gravity, Adami walls, the no-penetration correction, the
approach-gated wall tension, Fickian or delta-plus shifting; and with kdk delta-SPH, open ends
(``gpu_open_ends.py``) and rigid bodies (``gpu_bodies.py``); from the same pair terms as the CPU
step (``pairs.gather`` + ``terms.py``). Not ISPH, not float32 storage (``cuda_stepper.unsupported``).
``cuda_stepper.CudaStepper`` runs it. Its kernels call the CPU passes' per-particle
functions (``wcsph.adami_state``, ``wcsph.fluid_rates`` and those ``gpu_schemes.py`` lists);
the other per-particle bodies (``per_particle.py``) are plain ``@njit(inline="always")`` functions, which numba-cuda compiles
for the GPU as device functions and the CUDA simulator (``NUMBA_ENABLE_CUDASIM=1``) calls as CPU
code.
"""

from __future__ import annotations

import os

import numpy as np

# numba-cuda <= 0.30 names np.row_stack, which numpy 2.5 removed (an alias of vstack)
if not hasattr(np, "row_stack"):
    np.row_stack = np.vstack

# numba reads NUMBA_ENABLE_CUDASIM into its config when numba is imported and again only when it
# compiles something; numba.cuda picks the simulator or the driver from that config when it is
# first imported. Read the environment again first, so that a variable set after numba's import
# (the tests set it when no GPU is present) decides, not whether a compile happened in between.
from numba.core import config as _numba_config  # noqa: E402

_numba_config.reload_config()


def simulated() -> bool:
    """True when numba-cuda runs its CPU simulator (NUMBA_ENABLE_CUDASIM=1)."""
    return os.environ.get("NUMBA_ENABLE_CUDASIM", "0") not in ("", "0")


def lock_simulator_shared_arrays() -> None:
    """Make the simulator's ``cuda.shared.array`` safe for the block's threads (call after
    numba.cuda is imported, under the simulator only).

    numba-cuda <= 0.30's simulator runs each CUDA thread as a Python thread and hands out a
    block's shared array from a dict keyed by the calling line, filled on first use without a
    lock: a thread switched out between its lookup and its store gets an array of its own, never
    written by the others, and reads np.empty's garbage (a prefix sum gave a cell cursor of
    -4.6e18, the float bits of -0.4075; a block's max-reduction a wrong |a|^2 and so another dt:
    the CUDA tests' intermittent failures). Same keys, same arrays, under a lock."""
    import sys
    import threading

    from numba.core import types
    from numba.cuda.simulator import kernelapi
    from numba.np import numpy_support

    shared = kernelapi.FakeCUDAShared
    if getattr(shared, "_wavesph_locked", False):
        return
    plain = shared.array
    lock = threading.Lock()

    def array(self, shape, dtype, alignment=None):  # noqa: ANN001, ANN202 (the simulator's API)
        if shape == 0 or alignment is not None:  # dynamic shared memory is one buffer already
            return plain(self, shape, dtype, alignment)
        if isinstance(dtype, types.Type):
            dtype = numpy_support.as_dtype(dtype)
        caller = sys._getframe(1)
        key = (caller.f_code.co_filename, caller.f_lineno)
        with lock:
            out = self._allocations.get(key)
            if out is None:
                out = self._allocations[key] = np.empty(shape, dtype)
        return out

    shared.array = array
    shared._wavesph_locked = True


def unavailable_reason() -> str | None:
    """None if CUDA kernels can run here (a GPU, or the simulator), else a one-line reason."""
    try:
        from numba import cuda
    except ImportError as exc:  # numba-cuda not installed
        return f"numba-cuda is not installed ({exc}); pip install 'numba-cuda[cu13]'"
    if simulated():
        return None
    try:
        if not cuda.is_available():
            return "no CUDA GPU or driver found (set NUMBA_ENABLE_CUDASIM=1 for the simulator)"
    except Exception as exc:  # a broken driver or toolkit
        return f"CUDA unusable: {exc}"
    return None


def device_name() -> str:
    """The GPU the kernels run on (for meta.json and benchmarks), or the simulator."""
    if simulated():
        return "numba-cuda simulator"
    from numba import cuda
    name = cuda.get_current_device().name
    return name.decode() if isinstance(name, bytes) else str(name)
