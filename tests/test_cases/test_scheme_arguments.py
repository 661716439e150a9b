"""The benches' scheme options (wavesph.cases.schemes): what a command line puts in [scheme]."""

from __future__ import annotations

import argparse

from sph_core.scene import Scheme
from wavesph.cases.schemes import add_scheme_arguments, scheme_from_args


def parsed(*argv: str) -> dict:
    ap = argparse.ArgumentParser()
    add_scheme_arguments(ap)
    return scheme_from_args(ap.parse_args(list(argv)))


def test_isph_options_reach_the_scheme_table_and_validate():
    """The ISPH wave flume's options (docs/physics/isph.md) land in [scheme] and the scene
    accepts them; options left out keep the scene's defaults."""
    table = parsed("--scheme", "isph", "--isph-density-relaxation", "0.05", "--isph-wall-stop",
                   "100", "--isph-relaxation-zone", "0.4")
    assert table == {"kind": "isph", "isph_density_relaxation": 0.05, "isph_wall_stop": 100.0,
                     "isph_relaxation_zone": 0.4}
    sch = Scheme(**table)
    assert sch.isph_relaxation_zone == 0.4 and sch.isph_relaxation_time == 0.2
    assert parsed("--scheme", "isph") == {"kind": "isph"}


def test_isph_options_do_not_leak_into_other_schemes():
    assert parsed("--scheme", "wcsph", "--isph-relaxation-zone", "0.4") == {"kind": "wcsph"}
