"""The TOML scene of `wavesph waves`: grid, bathymetry, wave, sponges, filter, gauges, output.

Validated by pydantic v2 models (extra="forbid"): a bad or misspelt entry is reported with its
field path. Example: examples/waves/beji_battjes.toml.
"""

from __future__ import annotations

import tomllib
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from pydantic import AliasChoices, BaseModel, ConfigDict, Field, ValidationError, model_validator

from wave_client.theories.linear import wavenumber

from .solver import BoussinesqModel

BREAKING_H_OVER_D = 0.78       # McCowan's solitary-wave limit: a higher wave breaks before it gets there
MICHE = 0.142                  # Miche's steepness limit H/L = 0.142 tanh(kd)
KD_MAX = 3.0                   # Nwogu (z_alpha = -0.531 h): phase speed within 0.5 % of Airy to kd = 3 (2.7 % at 4)
MIN_POINTS_PER_WAVELENGTH = 10  # grid nodes per wavelength of the primary wave, at the shallowest depth


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class Grid(_Strict):
    x_start: float = Field(description="left end of the grid (a reflective wall) [m]")
    x_end: float = Field(description="right end of the grid (a reflective wall) [m]")
    dx: float = Field(gt=0, description="grid spacing [m]")
    dt: float | None = Field(default=None, gt=0, description="time step [s]; default from courant")
    courant: float = Field(default=0.4, gt=0, le=1.0, description="dt = courant dx / sqrt(g h_max)")
    t_end: float = Field(gt=0, description="simulated duration [s]")

    @model_validator(mode="after")
    def _ordered(self) -> "Grid":
        if not self.x_end > self.x_start:
            raise ValueError(f"x_end ({self.x_end}) must be greater than x_start ({self.x_start})")
        return self


class Bathymetry(_Strict):
    """Piecewise-linear still-water depth, held constant beyond the end points."""

    x: list[float] = Field(min_length=1, description="positions [m], increasing")
    depth: list[float] = Field(min_length=1, description="still-water depth at x [m], > 0")

    @model_validator(mode="after")
    def _consistent(self) -> "Bathymetry":
        if len(self.x) != len(self.depth):
            raise ValueError(f"x ({len(self.x)} values) and depth ({len(self.depth)}) differ in length")
        if np.any(np.diff(self.x) <= 0):
            raise ValueError("x must increase strictly")
        if min(self.depth) <= 0:
            raise ValueError("depth must be > 0 everywhere (the model has no dry land)")
        return self


class RegularWave(_Strict):
    kind: Literal["regular"]
    # H and T as everywhere else in wavesph (CLI, [source], HTTP); height/period kept
    height: float = Field(gt=0, validation_alias=AliasChoices("H", "height"),
                          description="wave height H [m] (`H` or `height`)")
    period: float = Field(gt=0, validation_alias=AliasChoices("T", "period"),
                          description="wave period T [s] (`T` or `period`)")
    x_source: float = Field(description="centre of the source function [m] (flat bed around it)")
    ramp_periods: float = Field(default=3.0, ge=0, description="start-up ramp [periods]")
    delta: float = Field(default=0.5, gt=0, description="source width parameter of Wei et al. (1999)")


class SeriesWave(_Strict):
    kind: Literal["series"]
    file: str = Field(description="CSV with columns time [s], eta [m] (uniform time step; '#' comments), "
                                  "relative to the scene file")
    x_source: float = Field(description="centre of the source function [m] (flat bed around it)")
    ramp: float = Field(default=0.0, ge=0, description="start-up ramp [s]")
    delta: float = Field(default=0.5, gt=0, description="source width parameter of Wei et al. (1999)")
    kd_max: float = Field(default=3.0, gt=0, description="drop components with k d above this")


class Sponge(_Strict):
    left: float = Field(default=0.0, ge=0, description="width of the left sponge layer [m]")
    right: float = Field(default=0.0, ge=0, description="width of the right sponge layer [m]")
    damping: float | None = Field(default=None, ge=0, description="peak damping rate [1/s]")


class Filter(_Strict):
    every: int = Field(default=0, ge=0, description="Shapiro filter every this many steps (0: off)")


class Solver(_Strict):
    tol: float = Field(default=1e-4, gt=0, description="corrector convergence (relative change)")
    max_iter: int = Field(default=20, ge=1, description="corrector iteration cap")


class WaveGauges(_Strict):
    x: list[float] = Field(min_length=1, description="gauge positions [m]")
    names: list[str] | None = Field(default=None, description="column names (default eta_<x>m)")

    @model_validator(mode="after")
    def _names(self) -> "WaveGauges":
        if self.names is not None and len(self.names) != len(self.x):
            raise ValueError(f"names ({len(self.names)}) and x ({len(self.x)}) differ in length")
        return self

    def columns(self) -> list[str]:
        return list(self.names) if self.names else [f"eta_{x:g}m" for x in self.x]


class Coupling(_Strict):
    """Used by `wavesph couple --model boussinesq`; ignored by `wavesph waves`."""

    x: float | None = Field(default=None, description="coupling boundary (SPH inlet) position [m] in "
                                                       "model coordinates; default grid.x_end")
    two_way: bool = Field(default=True, description="impose SPH elevation/velocity back (False: "
                                                    "absorption-only)")


class WaveOutput(_Strict):
    csv: str = Field(default="gauges.csv", description="gauge CSV path (relative to the working directory)")
    every: float | None = Field(default=None, gt=0, description="sampling interval [s] (default dt)")


class WaveScene(_Strict):
    grid: Grid
    bathymetry: Bathymetry
    wave: Annotated[RegularWave | SeriesWave, Field(discriminator="kind")]
    sponge: Sponge = Sponge()
    filter: Filter = Filter()
    solver: Solver = Solver()
    gauges: WaveGauges
    output: WaveOutput = WaveOutput()
    coupling: Coupling = Coupling()

    @model_validator(mode="after")
    def _inside(self) -> "WaveScene":
        g = self.grid
        bad = [x for x in self.gauges.x if not g.x_start <= x <= g.x_end]
        if bad:
            raise ValueError(f"gauges.x {bad} lie outside the grid [{g.x_start}, {g.x_end}]")
        if not g.x_start < self.wave.x_source < g.x_end:
            raise ValueError(f"wave.x_source ({self.wave.x_source}) lies outside the grid")
        xc = self.coupling.x
        if xc is not None and not g.x_start < xc <= g.x_end:
            raise ValueError(f"coupling.x ({xc}) lies outside the grid")
        if self.sponge.left + self.sponge.right >= g.x_end - g.x_start:
            raise ValueError("sponge.left + sponge.right must be shorter than the grid")
        if isinstance(self.wave, RegularWave):
            self._wave_fits()
        return self

    def _wave_fits(self) -> None:
        """Cross-field checks of a regular wave against the depth and the grid, before a run:
        one clear error instead of a run that blows up or silently leaves the model's range."""
        w, b = self.wave, self.bathymetry
        d = float(np.interp(w.x_source, b.x, b.depth))
        k = float(wavenumber(2 * np.pi / w.period, d))
        if w.height / d > BREAKING_H_OVER_D:
            raise ValueError(f"wave.height: H/d = {w.height / d:.2f} at the source (d = {d:g} m) is "
                             f"above the breaking limit {BREAKING_H_OVER_D} (McCowan 1894): the wave "
                             "cannot exist there")
        steep = MICHE * np.tanh(k * d)
        if w.height * k / (2 * np.pi) > steep:
            raise ValueError(f"wave.height: H/L = {w.height * k / (2 * np.pi):.3f} at the source is "
                             f"above the steepness limit 0.142 tanh(kd) = {steep:.3f} (Miche 1944)")
        if k * d > KD_MAX:
            raise ValueError(f"wave.period: kd = {k * d:.2f} at the source (d = {d:g} m) is outside "
                             f"the model's range kd <= {KD_MAX} (Nwogu's extended equations): use a "
                             "longer period or a shallower source")
        d_min = min(b.depth)
        per_wavelength = 2 * np.pi / float(wavenumber(2 * np.pi / w.period, d_min)) / self.grid.dx
        if per_wavelength < MIN_POINTS_PER_WAVELENGTH:
            raise ValueError(f"grid.dx: {per_wavelength:.1f} points per wavelength where the water "
                             f"is shallowest (d = {d_min:g} m); at least {MIN_POINTS_PER_WAVELENGTH} "
                             "are needed")


class WaveSceneError(ValueError):
    """A scene file that cannot be read or is invalid; the message names the fields."""


def load_wave_scene(path: str | Path) -> WaveScene:
    """Read and validate a `wavesph waves` TOML scene."""
    path = Path(path)
    try:
        data = tomllib.loads(path.read_text())
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise WaveSceneError(f"{path}: {exc}") from exc
    try:
        return WaveScene.model_validate(data)
    except ValidationError as exc:
        lines = [": ".join(filter(None, (".".join(str(p) for p in e["loc"]),
                                         e["msg"].removeprefix("Value error, "))))
                 for e in exc.errors()]
        raise WaveSceneError(f"{path}: invalid scene: " + "; ".join(lines)) from exc


def read_series(path: Path) -> tuple[np.ndarray, np.ndarray]:
    """Time [s] and eta [m] columns of a CSV (header row and '#' comment lines skipped)."""
    try:
        data = np.genfromtxt(path, delimiter=",", comments="#", skip_header=0, dtype=float)
    except OSError as exc:
        raise WaveSceneError(f"wave.file: {exc}") from exc
    if data.ndim != 2 or data.shape[1] < 2:
        raise WaveSceneError(f"wave.file {path}: need two columns time, eta")
    data = data[~np.isnan(data).any(axis=1)]  # a header row reads as NaN
    return data[:, 0], data[:, 1]


def build_model(scene: WaveScene, base_dir: Path | None = None) -> BoussinesqModel:
    """The model of a scene, with its source set (series files relative to base_dir)."""
    g = scene.grid
    model = BoussinesqModel(
        g.x_start, g.x_end, g.dx, (scene.bathymetry.x, scene.bathymetry.depth), dt=g.dt, courant=g.courant,
        sponge_left=scene.sponge.left, sponge_right=scene.sponge.right, sponge_damping=scene.sponge.damping,
        filter_every=scene.filter.every, tol=scene.solver.tol, max_iter=scene.solver.max_iter,
        x_couple=scene.coupling.x, two_way=scene.coupling.two_way)
    w = scene.wave
    if isinstance(w, RegularWave):
        model.set_regular_wave(w.x_source, w.height, w.period, w.ramp_periods, w.delta)
    else:
        t, eta = read_series((base_dir or Path.cwd()) / w.file)
        model.set_series_wave(w.x_source, t, eta, w.ramp, w.delta, w.kd_max)
    return model
