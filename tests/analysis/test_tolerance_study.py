"""ToleranceStudy's config: each declared range enforced exactly at its edges, the error naming
the field, the value and the allowed range in full; the combinations it refuses."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import assert_bounds
from rtsgeom.analysis.tolerance.config import MonteCarlo
from rtsgeom.analysis.tolerance.draws import Bounds
from rtsgeom.analysis.tolerance.study import ToleranceStudy
from rtsgeom.errors import ParameterError

BOUNDS = [
    ("spec_deg", [1e-6, 90.0],
     [(0.0, "ToleranceStudy: spec_deg = 0: must be in [1e-06, 90] deg"),
      (90.5, "ToleranceStudy: spec_deg = 90.5: must be in [1e-06, 90] deg")]),
    ("points", [3, 201], [(2, "ToleranceStudy: points = 2: must be in [3, 201]"),
                          (202, "ToleranceStudy: points = 202: must be in [3, 201]")]),
    ("verify", [0, 10_000], [(-1, "ToleranceStudy: verify = -1: must be in [0, 10000]"),
                             (10_001, "ToleranceStudy: verify = 10001: must be in [0, 10000]")]),
    ("invert_yield", [None, 1.0, 1e-9],
     [(0.0, "ToleranceStudy: invert_yield = 0: must be in (0, 1]"),
      (1.5, "ToleranceStudy: invert_yield = 1.5: must be in (0, 1]")]),
    ("invert_axis", ["all", "radial", "tangential", "height"],
     [("yaw", "ToleranceStudy: invert_axis = 'yaw': must be one of all, radial, tangential, "
              "height")]),
    ("mc", [MonteCarlo(1), MonteCarlo(10_000_000)],
     [(MonteCarlo(0), "ToleranceStudy: draws = 0: must be in [1, 1e+07]"),
      (None, "ToleranceStudy: mc must be a MonteCarlo")]),
    ("bounds", [Bounds(), Bounds((1e-3, 0.0, 0.0), 0.01)],
     [((1e-4,) * 3, "ToleranceStudy: bounds must be a Bounds (the error scales, SI)"),
      (Bounds((-1e-4, 0.0, 0.0)), "tolerance bounds [-0.0001, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, "
                                  "0.0]: must be finite and >= 0"),
      (Bounds(rut_yaw_rad=float("nan")), "tolerance bounds [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, "
                                         "0.0, nan]: must be finite and >= 0")]),
]


@pytest.mark.parametrize("name, ok, bad", BOUNDS, ids=[b[0] for b in BOUNDS])
def test_tolerance_study_enforces_each_range_at_its_edges(name, ok, bad):
    assert_bounds(lambda v: ToleranceStudy(**{name: v}), ok, bad)


def test_tolerance_study_takes_a_cell_or_a_pair_not_both():
    ToleranceStudy(cell="all")
    ToleranceStudy(pair=(0, 1))
    with pytest.raises(ParameterError) as exc:
        ToleranceStudy(cell="all", pair=(0, 1))
    assert str(exc.value) == ("ToleranceStudy: cell and pair: give one of them (the cell study "
                              "is of the cell's front ends)")


def test_tolerance_study_cases_and_defaults():
    from rtsgeom.analysis.tolerance.phasors import CASES, NOMINAL_AMPLITUDES
    assert ToleranceStudy().cases == CASES == ("uncalibrated", "calibrated")
    assert ToleranceStudy(nominal_amplitudes=True).cases == CASES + (NOMINAL_AMPLITUDES,)
    d = ToleranceStudy()
    assert (d.bounds, d.pair, d.cell, d.mc, d.spec_deg, d.points, d.verify, d.invert_yield,
            d.invert_axis, d.sigma_level, d.keep_draws) == (
        Bounds((1e-4,) * 3), None, None, MonteCarlo(), 0.1, 21, 0, None, "all", None, False)


def test_a_scene_with_its_own_errors_gets_the_whole_warning(default_scene):
    from conftest import DRAWS_REPLACE_TEXT, moved_front_end, the_warnings
    from rtsgeom.errors import NominalSetupWarning
    study = ToleranceStudy(pair=(0, 1), mc=MonteCarlo(20), points=5)
    assert the_warnings(lambda: study(moved_front_end(default_scene)), NominalSetupWarning) == [
        "tolerance " + DRAWS_REPLACE_TEXT]
    assert the_warnings(lambda: study(default_scene), NominalSetupWarning) == []


def test_the_combinations_the_study_does_not_model_are_refused(default_scene, sphere_scene,
                                                              crossing_bench):
    from conftest import assert_refused
    mc = MonteCarlo(10)
    rot = Bounds((1e-4,) * 3, 1e-3)
    verify = ("verify: only for one pair with offsets (not pair='all', rotations or RuT-pose "
              "errors)")
    assert_refused(lambda: ToleranceStudy(pair="all", verify=2, mc=mc, points=3)(crossing_bench),
                   verify)
    assert_refused(lambda: ToleranceStudy(rot, pair=(0, 1), verify=2, mc=mc, points=3)(
        default_scene), verify)
    assert_refused(lambda: ToleranceStudy(Bounds((1e-4,) * 3, rut_yaw_rad=1e-3), pair=(0, 1),
                                          verify=1, mc=mc, points=3)(default_scene), verify)
    assert_refused(lambda: ToleranceStudy(cell="all", nominal_amplitudes=True, mc=mc, points=3)(
        sphere_scene), "nominal_amplitudes: only for the pair study (the cell study designs its "
                       "amplitudes once, at the bin centre)")
    for kw in ({"invert_yield": 0.9}, {"verify": 1}):
        assert_refused(lambda: ToleranceStudy(rot, cell="all", mc=mc, points=3, **kw)(
            sphere_scene), "verify, invert_yield: only without rotation or RuT-pose errors so far")
    assert_refused(lambda: ToleranceStudy(cell="all", mc=mc, points=3)(default_scene),
                   "cell: tolerance --cell needs a RuT that beamforms in azimuth and elevation "
                   "(an array with elevation extent, e.g. radar.use_elevation_tx = true)")
    for cell, shown in (((0, 1), "[0, 1]"), ((0, 1, 9), "[0, 1, 9]"), ((0, 1, 1), "[0, 1, 1]"),
                        ((0, 1, 2, 3, 0), "[0, 0, 1, 2, 3]")):  # shown sorted
        assert_refused(lambda: ToleranceStudy(cell=cell, mc=mc, points=3)(sphere_scene),
                       f"cell: cell {shown}: must be 3 or 4 distinct front-end indices in [0, 3]")


# -- the report's helpers and files, read whole --------------------------------------------


@pytest.mark.parametrize("points", [1, 3, 21, 61, 201])
def test_a_chunk_is_capped_by_its_memory_at_each_edge(points):
    """A chunk's bytes per draw 2000 per point plus 10 000; the chunk at most 256 MiB over
    that, never below 100 draws: each edge from both sides."""
    from rtsgeom.analysis.tolerance.study import (CHUNK_MEMORY_BYTES, capped_chunk,
                                                  chunk_bytes_per_draw)
    per = 2000 * points + 10_000
    assert chunk_bytes_per_draw(points) == per and CHUNK_MEMORY_BYTES == 256 * 2 ** 20
    cap = 256 * 2 ** 20 // per
    for chunk in (1, 99, 100, 101, cap - 1, cap, cap + 1, 10 ** 9):
        assert capped_chunk(chunk, points) == max(100, min(chunk, cap)), chunk
    assert capped_chunk(99.9, points) == 100  # int() of the chunk first


@pytest.fixture(scope="module")
def pair01(default_scene):
    from rtsgeom.analysis.tolerance.montecarlo import ToleranceModel
    from rtsgeom.analysis.tolerance.phasors import ChannelPhasors
    from rtsgeom.geometry import build_setup
    return ToleranceModel.of(ChannelPhasors.build(build_setup(default_scene), (0, 1), 3))


def _with(scene, **per_fe):
    """``scene`` with front end q's fields ``per_fe[f'fe{q}']`` (the file's keys)."""
    import rtsgeom
    fes = list(scene.rts.front_ends)
    for key, changes in per_fe.items():
        q = int(key[2:])
        fes[q] = rtsgeom.replace(fes[q], **changes)
    return rtsgeom.replace(scene, rts=rtsgeom.replace(scene.rts, front_ends=tuple(fes)))


@pytest.mark.parametrize("changes, fields", [
    ({"fe0": {"radial_offset_mm": 0.3}}, ["rts.front_ends[0].radial_offset_mm"]),
    ({"fe1": {"tangential_offset_mm": -0.2}}, ["rts.front_ends[1].tangential_offset_mm"]),
    ({"fe0": {"height_offset_mm": 0.1}, "fe1": {"radial_offset_mm": 0.2,
                                                "tangential_offset_mm": 0.1}},
     ["rts.front_ends[0].height_offset_mm", "rts.front_ends[1].radial_offset_mm",
      "rts.front_ends[1].tangential_offset_mm"]),
])
def test_the_scenes_own_offsets_effect_in_full(default_scene, pair01, changes, fields):
    """The scene's own offsets (only the non-zero ones named, in front-end and axis order) on
    the model's one setup: each case's worst |error| of that setup."""
    from rtsgeom.analysis.tolerance.phasors import CASES
    from rtsgeom.analysis.tolerance.study import scene_offsets_effect
    scene = _with(default_scene, **changes)
    off = np.zeros((1, 2, 3))
    for key, ch in changes.items():
        for name, v in ch.items():
            off[0, int(key[2:]), ("radial_offset_mm", "tangential_offset_mm",
                                  "height_offset_mm").index(name)] = v * 1e-3
    worst = pair01.sets[0].evaluate(off, CASES)
    want = {"fields": fields, "model": "phasor level, one setup with the scene's offsets, "
                                       "target at the bin centre",
            "uncalibrated_deg": float(np.max(np.abs(worst["uncalibrated"][0]))),
            "calibrated_deg": float(np.max(np.abs(worst["calibrated"][0])))}
    got = scene_offsets_effect(scene, pair01)
    assert got == want
    assert got["uncalibrated_deg"] != got["calibrated_deg"]  # the cases told apart


@pytest.mark.parametrize("other", [{}, {"yaw_offset_deg": 0.1}, {"pitch_offset_deg": 0.1},
                                   {"gain_offset_db": 0.5}, {"phase_offset_deg": 3.0}])
def test_no_offsets_effect_without_offsets_or_with_errors_beyond_them(default_scene, pair01,
                                                                      other):
    """None where the pair has no offsets, or has an error the phasor model does not take as
    an offset (a rotation, a gain or a phase) on either front end."""
    from rtsgeom.analysis.tolerance.study import scene_offsets_effect
    assert scene_offsets_effect(_with(default_scene, fe0=other) if other else default_scene,
                                pair01) is None
    if other:
        both = _with(default_scene, fe0={"radial_offset_mm": 0.2}, fe1=other)
        assert scene_offsets_effect(both, pair01) is None
        assert scene_offsets_effect(_with(default_scene, fe0={"radial_offset_mm": 0.2}),
                                    pair01) is not None


def test_which_study_a_scene_gets(default_scene, sphere_scene):
    """The cell of all front ends where the RuT beamforms in 2-D with 3 or 4 front ends and
    neither is given; a given cell or pair wins."""
    assert ToleranceStudy().wants_cell(sphere_scene)
    assert not ToleranceStudy().wants_cell(default_scene)
    assert not ToleranceStudy(pair=(0, 1)).wants_cell(sphere_scene)
    assert ToleranceStudy(cell="all").wants_cell(default_scene)
    import rtsgeom
    fes = sphere_scene.rts.front_ends
    for n, cell in ((2, False), (3, True), (4, True)):
        fewer = rtsgeom.replace(sphere_scene, rts=rtsgeom.replace(sphere_scene.rts,
                                                                  front_ends=fes[:n]))
        assert ToleranceStudy().wants_cell(fewer) is cell, n


def test_an_arcs_search_runs_on_every_axis_only(crossing_bench):
    from conftest import assert_refused
    assert_refused(lambda: ToleranceStudy(pair="all", invert_yield=0.9, invert_axis="radial",
                                          mc=MonteCarlo(5), points=3)(crossing_bench),
                   "ToleranceStudy: invert_axis = 'radial': must be 'all' for an arc (its "
                   "inversion scales every error together)")


@pytest.fixture(scope="module")
def reports(default_scene, sphere_scene):
    import warnings
    from conftest import moved_front_end
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        pair = ToleranceStudy(pair=(0, 1), mc=MonteCarlo(12, seed=3), points=3)(
            moved_front_end(default_scene))
    cell = ToleranceStudy(cell="all", mc=MonteCarlo(10, seed=4, subbin=True), points=3)(
        sphere_scene)
    centre = ToleranceStudy(cell="all", mc=MonteCarlo(6, seed=4, subbin=False), points=3)(
        sphere_scene)
    return {"pair": pair, "cell": cell, "centre": centre}


@pytest.mark.parametrize("which", ["pair", "cell", "centre"])
def test_the_draws_file_in_full(reports, which, tmp_path):
    """tolerance_draws.npz: the drawn offsets (the draws' own stream, rebuilt), a pair's front
    ends, delays, range offsets and worst errors as columns of one pair, a cell's front ends,
    delays per channel, sub-bin positions (zeros at the bin centre) and worst errors per
    angle; write() makes exactly the three files and the JSON is the report's."""
    import json
    from rtsgeom.analysis.tolerance.draws import draw_offsets
    rep = reports[which]
    res, m = rep.run, rep.run.model.sets[0]
    assert rep.kind == ("pair" if which == "pair" else "cell")
    want = {"offsets_m": draw_offsets(res.seed, res.draws, res.sigma_m, res.distribution,
                                      len(m.front_ends))}
    if which == "pair":
        want.update(pairs=np.array([[0, 1]]), delay_s=res.delay_s.reshape(-1, 1),
                    range_offset_m=res.range_offset_m.reshape(-1, 1),
                    uncalibrated_deg=res.worst_error_deg["uncalibrated"].reshape(-1, 1),
                    calibrated_deg=res.worst_error_deg["calibrated"].reshape(-1, 1))
    else:
        sub = (np.zeros(res.draws, int) if which == "centre" else res.subbin_steps)
        want.update(cell=np.arange(4), delay_s=res.delay_s, range_offset_m=res.range_offset_m,
                    subbin_steps=sub, uncalibrated_deg=res.worst_error_deg["uncalibrated"],
                    calibrated_deg=res.worst_error_deg["calibrated"])
    if which == "cell":
        assert res.subbin_steps is not None and np.any(res.subbin_steps != 0)
    got = rep.draw_arrays()
    assert list(got) == list(want)
    for k, v in want.items():
        assert np.array_equal(got[k], v) and got[k].shape == np.shape(v), k
    assert want["offsets_m"].shape == (res.draws, len(m.front_ends), 3)
    names = rep.write(tmp_path)
    assert names == ["tolerance.png", "tolerance.json", "tolerance_draws.npz"]
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(names)
    with np.load(tmp_path / "tolerance_draws.npz") as npz:
        assert sorted(npz.files) == sorted(want)
        for k, v in want.items():
            assert np.array_equal(npz[k], v), k
    assert json.loads((tmp_path / "tolerance.json").read_text()) == json.loads(
        json.dumps(rep.to_dict()))


def test_the_reports_summary_adds_its_check_and_search(reports):
    """The run's rows, then the chain check's largest difference and each case's search
    result (an arc's factor, else its sigmas)."""
    import dataclasses
    from types import SimpleNamespace
    rep = reports["pair"]
    title, rows = rep.run._summary()
    assert rep._summary() == (title, rows)
    more = dataclasses.replace(rep, verify=SimpleNamespace(max_difference_deg=1.5e-5),
                               inversion={"uncalibrated": {"factor": 0.5},
                                          "calibrated": {"sigma_mm": {"radial": 0.2}}})
    assert more._summary() == (title, rows + [
        ("verify |chain - model| (deg)", 1.5e-5), ("search (uncalibrated)", 0.5),
        ("search (calibrated)", {"radial": 0.2})])
    assert rep._columns().keys() == rep.run._columns().keys()
