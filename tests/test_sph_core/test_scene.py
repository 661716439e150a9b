"""Scene configs: the shipped examples load, and bad configs name the offending field."""

import copy
from pathlib import Path

import pytest

from sph_core.scene import SceneError, datum_mismatch, divisor_text, load_scene, make_scene

ROOT = Path(__file__).resolve().parents[2]
BASE = {"dp": 0.01, "t_end": 1.0, "tank": {"x0": 0, "x1": 1, "z0": 0, "z1": 1},
        "water_blocks": [{"x0": 0, "x1": 0.5, "z0": 0, "z1": 0.5}]}


@pytest.mark.parametrize("name", ["still_water_tank.toml", "dambreak_martin_moyce.toml"])
def test_example_scenes_load(name):
    scene = load_scene(ROOT / "examples" / "scenes" / name)
    assert scene.dp > 0 and scene.t_end > 0 and scene.water_blocks


def test_default_speed_of_sound():
    s = make_scene(BASE)
    assert s.c0 == pytest.approx(10 * (2 * 9.81 * 0.5) ** 0.5)
    assert s.h == pytest.approx(2.0 * 0.01)   # h/dp 2 by default (issue 11, wave decay study)


@pytest.mark.parametrize("edit, field", [
    (lambda d: d["water_blocks"][0].update(z1=-1.0), "water_blocks.0.z1"),
    (lambda d: d.update(dp=-0.01), "dp"),
    (lambda d: d["tank"].update(lenght=4.0), "tank.lenght"),
    (lambda d: d.update(constants={"cfl": 2.0}), "constants.cfl"),
    (lambda d: d.update(probes=[{"kind": "point", "name": "a", "x": 5.0, "z": 0.1}]), "probes.0.x"),
    (lambda d: d.update(probes=[{"kind": "elevation", "name": "g", "x": 0.5, "threshold": 2}]),
     "probes.0.threshold"),
    (lambda d: d.update(beds=[{"points": [[0.5, 0.0], [0.2, 0.3]]}]), "beds.0.points"),
    (lambda d: d.pop("dp"), "dp"),
    (lambda d: d["water_blocks"][0].update(x1=2.0), "water_blocks.0"),
])
def test_config_errors_name_the_field(edit, field):
    data = copy.deepcopy(BASE)
    edit(data)
    with pytest.raises(SceneError) as info:
        make_scene(data)
    assert f"{field}:" in str(info.value)


def test_toml_errors(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text("dp = 0.01\n[tank\n")
    with pytest.raises(SceneError, match="not valid TOML"):
        load_scene(bad)
    with pytest.raises(SceneError, match="not found"):
        load_scene(tmp_path / "missing.toml")
    typo = tmp_path / "typo.toml"
    typo.write_text('dp = 0.01\nt_end = 1\n[tank]\nx0=0\nx1=1\nz0=0\nz1=1\n'
                    '[[water_blocks]]\nx0=0\nx1=1\nz0=0\nz1=0.5\nheigth=2\n')
    with pytest.raises(SceneError, match=r"water_blocks\.0\.heigth: Extra inputs"):
        load_scene(typo)


@pytest.mark.parametrize("swl,top,message", [
    (0.5, 0.5, "between the tank's floor"),     # still water at the tank top: no freeboard
    (0.3, 0.2, "highest water block's top"),    # the blocks do not fill to the declared level
])
def test_still_water_level_is_checked_against_the_tank_and_the_water_blocks(swl, top, message):
    scene = {"dp": 0.02, "t_end": 1.0, "still_water_level": swl,
             "tank": {"x0": 0.0, "x1": 1.0, "z0": 0.0, "z1": 0.5},
             "water_blocks": [{"x0": 0.0, "x1": 1.0, "z0": 0.0, "z1": top}]}
    with pytest.raises(SceneError, match=message):
        make_scene(scene)
    make_scene({**scene, "still_water_level": 0.2, "water_blocks": [
        {"x0": 0.0, "x1": 1.0, "z0": 0.0, "z1": 0.2}]})   # consistent: accepted


def test_a_dp_that_does_not_divide_the_depth_is_refused_with_divisors_to_pick():
    # 0.3 m at dp 0.04 is 7.5 rows: the particles fill to 0.28 m and every elevation gauge
    # would read -0.02 m in still water (a third of H = 0.06)
    scene = {"dp": 0.04, "t_end": 1.0, "still_water_level": 0.3,
             "tank": {"x0": 0.0, "x1": 2.0, "z0": 0.0, "z1": 0.6},
             "water_blocks": [{"x0": 0.0, "x1": 2.0, "z0": 0.0, "z1": 0.3}]}
    with pytest.raises(SceneError, match=r"still_water_level: 0\.3 m is 7\.5 dp .* fill to 0\.28 m"
                                         r".* read -0\.02 m .* e\.g\. 0\.0375 or 0\.04286 m"):
        make_scene(scene)
    for dp in (0.0375, 0.04286, 0.03, 0.1 / 3):   # divisors (the last one as a float)
        assert make_scene({**scene, "dp": dp}).dp == dp


@pytest.mark.parametrize("depth, rows", [(0.3, 17), (0.24, 17), (0.7, 75), (0.7, 38), (1.0, 3),
                                         (0.3, 16), (0.24, 400)])
def test_a_suggested_divisor_is_one_the_scene_accepts(depth, rows):
    # four digits are not always enough: 0.3 m / 17 written 0.01765 fills to 0.30005 m, and the
    # refusal's own suggestion, or a plan's dp, must not be refused in turn
    text = divisor_text(depth, depth / rows)
    assert round(depth / float(text)) == rows and len(text) <= len(repr(depth / rows))
    scene = {"dp": float(text), "t_end": 1.0, "still_water_level": depth,
             "tank": {"x0": 0.0, "x1": 1.0, "z0": 0.0, "z1": 2 * depth},
             "water_blocks": [{"x0": 0.0, "x1": 1.0, "z0": 0.0, "z1": depth}]}
    assert datum_mismatch(depth, depth, 0.0, float(text)) is None
    digits = len(text.replace(".", "").lstrip("0"))
    if digits > 1:   # the shortest: one significant digit fewer is another divisor or refused
        short = float(f"{depth / rows:.{digits - 1}g}")
        assert round(depth / short) != rows or datum_mismatch(depth, depth, 0.0, short) is not None
    if rows < 100:   # (a 0.24 m deep, 0.0006 m lattice is not built here)
        assert make_scene(scene).dp == float(text)

