"""Checkpoints as portable npz files (sph_core.checkpoint_file): a run restored from the file
continues bit for bit, and the file holds no pickle."""

from __future__ import annotations

import zipfile

import numpy as np
import pytest

from sph_core.checkpoint_file import load_checkpoint, save_checkpoint
from sph_core.scene import make_scene
from sph_core.simulation import Simulation


def open_flume() -> dict:
    return {"name": "cp", "dp": 0.04, "t_end": 1.0, "still_water_level": 0.2,
            "tank": {"x0": 0.0, "x1": 1.2, "z0": 0.0, "z1": 0.4},
            "water_blocks": [{"x0": 0.0, "x1": 1.2, "z0": 0.0, "z1": 0.2}],
            "open_boundaries": [{"side": "left"}]}


def test_a_run_restored_from_the_npz_file_continues_bit_for_bit(tmp_path):
    sim = Simulation(make_scene(open_flume()))
    sim.advance_to(0.05)
    path = tmp_path / "state.npz"
    t_saved = sim.t
    save_checkpoint(path, sim.checkpoint())
    sim.advance_to(0.1)
    expected = sim.particles.f[:, : sim.particles.n].copy()
    sim.restore(load_checkpoint(path))
    assert sim.t == t_saved
    sim.advance_to(0.1)
    np.testing.assert_array_equal(sim.particles.f[:, : sim.particles.n], expected)
    # numpy's own reader without pickle opens it; no member is a pickle
    with np.load(path, allow_pickle=False) as z:
        assert "tree" in z.files
    with zipfile.ZipFile(path) as zf:
        assert all(not zf.read(n).startswith(b"\x80") for n in zf.namelist())


def test_a_file_that_is_not_a_checkpoint_is_refused(tmp_path):
    bad = tmp_path / "x.npz"
    np.savez(bad, a=np.zeros(3))
    with pytest.raises(ValueError, match="not a wavesph checkpoint"):
        load_checkpoint(bad)


def test_a_checkpoint_of_the_previous_field_layout_restores(tmp_path):
    """Checkpoints written before the kernel-correction rows (23 particle fields) still resume:
    the missing rows are per-step scratch; the run continues as from a full checkpoint."""
    import dataclasses

    sim = Simulation(make_scene(open_flume()))
    sim.advance_to(0.05)
    c = sim.checkpoint()
    sim.advance_to(0.1)
    expected = sim.particles.f[:, : sim.particles.n].copy()
    old = dataclasses.replace(c, f=c.f[:23])
    sim.restore(old)
    sim.advance_to(0.1)
    np.testing.assert_array_equal(sim.particles.f[:23, : sim.particles.n], expected[:23])
    bad = dataclasses.replace(c, f=c.f[:5])
    with pytest.raises(ValueError, match="particle fields"):
        sim.restore(bad)
