"""Checks that the fresh mutation sample (seed 11, benchmarks/mutation-report-seed11.md) found
missing: a path table's selection keeps every column, an object's clouds CSV keeps every
column, the design study draws with its own seed and announces its count, the studies' configs
accept what their docstrings promise and name the field they refuse."""

from __future__ import annotations

import csv
import io
import math

import numpy as np
import pytest

from rtsgeom.analysis.design import design_grid
from rtsgeom.analysis.design_study import DesignStudy
from rtsgeom.analysis.kpi.study import KpiStudy
from rtsgeom.analysis.objects import CLOUD_COLUMNS, clouds_csv
from rtsgeom.analysis.resolution import ResolutionStudy
from rtsgeom.analysis.tolerance.config import MonteCarlo
from rtsgeom.analysis.tolerance.study import ToleranceStudy
from rtsgeom.analysis.transfer import TransferStudy
from rtsgeom.errors import ParameterError
from rtsgeom.paths.table import Paths


@pytest.mark.parametrize("n", [1, 4, 9])
def test_a_selection_of_paths_keeps_every_column(n):
    """``Paths.select(mask)`` is every column indexed by the mask, what each bounce hit
    included (a sheet reflection's ``sheet`` must not turn into the default ``unknown``)."""
    rng = np.random.default_rng(n)
    bounces = rng.integers(0, 3, n)
    surfaces = np.array(["" if b == 0 else "+".join(["sheet"] * b) for b in bounces])
    p = Paths.build(np.arange(n) % 3, np.arange(n) % 2,
                    rng.integers(0, 3, n), rng.integers(0, 4, n), rng.uniform(1e-9, 2e-8, n),
                    rng.normal(size=n) + 1j * rng.normal(size=n), bounces,
                    np.where(bounces == 0, "los", "reflection"), "raytrace", surfaces)
    for mask in (np.ones(n, bool), np.arange(n) % 2 == 0, rng.random(n) < 0.5):
        s = p.select(mask)
        for col in ("front_end", "direction", "rut_tx", "rut_rx", "delay_s", "gain",
                    "bounces", "interactions", "surfaces"):
            np.testing.assert_array_equal(getattr(s, col), getattr(p, col)[mask], err_msg=col)
        assert s.method == p.method


def test_clouds_csv_writes_every_column_of_every_row():
    """One CSV row per detection with all of :data:`CLOUD_COLUMNS`: the numbers to six
    significant digits, a missing elevation (azimuth-only RuT) empty."""
    rng = np.random.default_rng(11)
    rows = [(f, src, k, *rng.uniform(-50, 50, 3), (np.nan if f % 2 else rng.uniform(-5, 5)),
             rng.uniform(-90, 0)) for f in range(4) for src in ("truth", "rts") for k in range(2)]
    got = list(csv.reader(io.StringIO(clouds_csv(rows))))
    assert tuple(got[0]) == CLOUD_COLUMNS
    assert len(got) == len(rows) + 1
    for r, line in zip(rows, got[1:]):
        assert len(line) == len(CLOUD_COLUMNS)
        assert line[:3] == [str(r[0]), r[1], str(r[2])]
        for x, text in zip(r[3:], line[3:]):
            if np.isfinite(x):
                assert float(text) == pytest.approx(x, rel=1e-5)
            else:
                assert text == ""


def test_the_design_study_draws_with_its_seed_and_announces_its_count(default_scene):
    """``DesignStudy(mc=MonteCarlo(seed=s))`` is ``design_grid(..., seed=s)`` (not the
    default seed's), and its progress opens with the number of designs to come."""
    calls = []
    radii, spacings = (1.0,), (8.0, 12.0)
    study = DesignStudy(radius_m=radii, spacing_deg=spacings, points=3,
                        mc=MonteCarlo(draws=30, seed=7,
                                      progress=lambda *a: calls.append(a)))
    got = study(default_scene).to_dataframe()
    want = design_grid(default_scene, (0, 1), list(radii), list(spacings), 0.1, 0.95, 30, 7,
                       points=3).to_dataframe()
    other = design_grid(default_scene, (0, 1), list(radii), list(spacings), 0.1, 0.95, 30, 0,
                        points=3).to_dataframe()
    assert got.equals(want)
    assert not got.equals(other)  # the seed matters at 30 draws
    assert calls[0] == ("designs", 0, len(radii) * len(spacings))


@pytest.mark.parametrize("sigma", [(0.1, 0.2, 0.3), [0.0, 0.05, 1.0]])
def test_kpi_study_takes_three_sigmas(sigma):
    """``sigma_mm`` is one number or three (radial, tangential, height)."""
    assert tuple(KpiStudy(sigma_mm=sigma).sigma_mm) == tuple(sigma)
    with pytest.raises(ParameterError, match="sigma_mm"):
        KpiStudy(sigma_mm=tuple(sigma)[:2])


@pytest.mark.parametrize("pairs", [((0,),), ((0, 1), (2,)), ((0, 1, 2),)])
def test_a_transfer_pair_is_two_front_ends(pairs):
    with pytest.raises(ParameterError, match=r"pairs\[\d\]"):
        TransferStudy(pairs=pairs)


@pytest.mark.parametrize("value", [0.0, -0.5, 1.5, math.nan])
def test_a_bad_invert_yield_is_named(value):
    with pytest.raises(ParameterError, match=r"invert_yield"):
        ToleranceStudy(invert_yield=value)


@pytest.mark.parametrize("seps", [(0.0,), (5.0, 121.0), (-1.0,)])
def test_a_bad_separation_says_the_allowed_range(seps):
    with pytest.raises(ParameterError, match=r"separations in \(0, 120\] deg"):
        ResolutionStudy(separations_deg=seps)


@pytest.mark.parametrize("radius_m, seed", [(None, 3), (1.6, 4)])
def test_identifying_a_nominal_radar_finds_no_antenna_errors(radius_m, seed):
    """The joint fit (``identify(..., radar_channels=True)``) of captures simulated on the
    nominal scene itself at 30 dB SNR: an identification of that scene, one fit per front
    end, every antenna's estimated gain and phase zero to within noise (1e-2)."""
    from conftest import DEFAULT_SCENE
    from rtsgeom import identify as ident_mod
    from rtsgeom.paths import exact_paths
    from rtsgeom.scene import load_scene
    scene = load_scene(DEFAULT_SCENE)
    rts = scene.rts if radius_m is None else scene.rts.evolve(arc_radius_m=radius_m)
    scene = scene.evolve(radar=scene.radar.evolve(snr_db=30.0), rts=rts)
    setup = ident_mod.setup_of(scene)
    paths = exact_paths(setup)
    caps = [ident_mod.simulate_capture(setup, q, seed=[seed, q], paths=paths)
            for q in range(setup.fe.count)]
    ident = ident_mod.identify(scene, caps, radar_channels=True)
    assert ident.scene is scene
    assert len(ident.fits) == setup.fe.count
    np.testing.assert_allclose(ident.radar.phase, 0.0, atol=1e-2)
    np.testing.assert_allclose(ident.radar.log_gain, 0.0, atol=1e-2)


@pytest.mark.parametrize("n_bad", [1, 4, 5, 9])
def test_bad_arc_radii_are_listed_four_at_most(default_scene, n_bad):
    """The error names the first bad radii, four at most (a long list stays one line)."""
    from rtsgeom.analysis.nearfield import nearfield
    bad = [-1.0 - k for k in range(n_bad)]
    with pytest.raises(ParameterError, match="arc radii") as err:
        nearfield(default_scene, [1.0] + bad, points=3)
    listed = str(err.value).split("got ")[1].removesuffix(" m").split(", ")
    assert [float(x) for x in listed] == bad[:4]
