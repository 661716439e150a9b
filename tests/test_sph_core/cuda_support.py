"""The shared set-up of the CUDA step's tests (test_cuda_*.py).

Importing this module picks the device: a GPU when one is present, else numba-cuda's simulator
(``NUMBA_ENABLE_CUDASIM=1``, set here, so the test modules import it before numba.cuda is first
imported: the CPU tests in the same session never import it). ``CUDA_TESTS`` is a module's
``pytestmark`` (the ``cuda`` marker, skipped without numba-cuda); ``device_session`` is the body
of a module fixture (skipped where the device is unavailable; the simulator's block threads
switch faster meanwhile); ``short_run`` and ``fluid_agrees`` are the whole-run comparison with
the CPU.
"""

from __future__ import annotations

import importlib.util
import os
import shutil
import sys
from contextlib import contextmanager

import numpy as np
import pytest

if "NUMBA_ENABLE_CUDASIM" not in os.environ and not (
        os.path.exists("/dev/nvidia0") or shutil.which("nvidia-smi")):
    os.environ["NUMBA_ENABLE_CUDASIM"] = "1"

needs_numba_cuda = pytest.mark.skipif(
    importlib.util.find_spec("numba_cuda") is None,
    reason="numba-cuda is not installed (pip install numba-cuda)")
CUDA_TESTS = [pytest.mark.cuda, needs_numba_cuda]

# the fluid's fields a whole run compares
FIELDS = ("x", "z", "vx", "vz", "rho", "p")


def skip_without_device() -> None:
    """Skip the test where sph_core.cuda cannot run (its one-line reason)."""
    from sph_core.cuda import unavailable_reason
    reason = unavailable_reason()
    if reason:
        pytest.skip(reason)


@contextmanager
def device_session():
    """A module fixture's set-up and tear-down: skipped without a usable device; meanwhile the
    simulator's block threads wait on each other far less (``sys.setswitchinterval(1e-4)``)."""
    skip_without_device()
    old = sys.getswitchinterval()
    sys.setswitchinterval(1e-4)
    try:
        yield
    finally:
        sys.setswitchinterval(old)


def stepper(sim):
    """A CudaStepper of ``sim`` (its particles copied to the device)."""
    from sph_core.cuda.cuda_stepper import CudaStepper
    return CudaStepper(sim)


def set_clock(st, dts=0.0, t=0.0, v2=0.0):
    """The device's clock at t with this step's dt ``dts`` (and the reduced max |v|^2 ``v2``),
    no t_stop, the control counters cleared."""
    from sph_core.cuda import gpu_kernels as K
    clk = np.zeros(K.N_CLK)
    clk[K.T], clk[K.DTS], clk[K.V2], clk[K.T_STOP] = t, dts, v2, np.inf
    st._put(st.clk, clk)
    st._put(st.ctl, np.zeros(K.N_CTL, dtype=np.int64))


def close(gpu, cpu, rel=1e-12):
    """Equal to round-off: |gpu - cpu| <= rel * max|cpu| (the CPU passes reassociate sums under
    fastmath, the GPU contracts to FMAs: the same terms, a few ulp apart)."""
    scale = max(float(np.abs(cpu).max()), 1e-300)
    np.testing.assert_allclose(gpu, cpu, rtol=0.0, atol=rel * scale)


def short_run(cpu, gpu, steps):
    """``steps`` steps of Simulation ``gpu`` on the device (then copied to the host) and of
    ``cpu`` on the CPU: the same step count, clock and next dt. Returns the stepper."""
    from sph_core.wcsph import ST_STEP_LIMIT
    st = stepper(gpu)
    assert st.advance_steps(steps) == ST_STEP_LIMIT
    st.to_host()
    cpu.advance_steps(steps)
    # what differs, in the message: an intermittent clock mismatch was seen once in CI
    a, b = cpu.fluid_state(), gpu.fluid_state()
    seen = (f"gpu t {gpu.t!r} dt {gpu.dt!r} steps {gpu.steps}, cpu t {cpu.t!r} dt {cpu.dt!r} "
            f"steps {cpu.steps}; max |gpu - cpu| / max |cpu|: "
            + str({k: float(np.abs(b[k] - a[k]).max() / max(np.abs(a[k]).max(), 1e-300))
                   for k in FIELDS if a[k].shape == b[k].shape}))
    assert gpu.steps == cpu.steps, seen
    assert gpu.t == pytest.approx(cpu.t, rel=1e-12), seen
    assert gpu.dt == pytest.approx(cpu.dt, rel=1e-10), seen
    return st


def fluid_agrees(cpu, gpu, rel=1e-10, label="max |gpu - cpu| / max |cpu|:", *extra):
    """The two Simulations' fluid: the same ids, every field of FIELDS within ``rel`` of its
    scale; prints the measured differences (``pytest -rP`` shows them) after ``label`` and
    before ``extra``. Returns the CPU's fluid_state()."""
    a, b = cpu.fluid_state(), gpu.fluid_state()
    np.testing.assert_array_equal(a["id"], b["id"])
    # a field that is zero throughout (vy in 2D) has no scale: its absolute difference
    print(label, {k: float(np.abs(b[k] - a[k]).max() / (np.abs(a[k]).max() or 1.0))
                  for k in a if k != "id"}, *extra)
    for key in FIELDS:
        close(b[key], a[key], rel=rel)
    return a
