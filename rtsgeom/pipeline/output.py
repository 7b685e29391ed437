"""The output folder of ``rtsgeom run``: detections as CSV, the summary, the range-Doppler and
range-angle maps (PNG, and as arrays in ``maps.npz|mat|nc``) and the self-contained
``report.html``, each as bytes or text from one :class:`~rtsgeom.pipeline.run.RunResult`, and
:func:`write_run`, the whole folder (what ``run`` writes, callable from Python)."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import numpy as np

from .._lib.io import write_bytes, write_json, write_text
from .._lib.parallel import Forked, fork_call
from ..radar.processing import range_angle_map
from ..scene.registry import MAP_FORMATS
from .info import scene_info
from .run import RunResult, label_detections, summary
from .view import setup_png, start_setup_view

__all__ = ["detections_csv", "figure_png", "map_arrays", "map_dataset", "maps_arrays",
           "MAP_FORMATS", "MAP_UNITS",
           "render_maps", "write_maps", "targets_table", "run_report_html",
           "start_setup_view", "write_run"]


def detections_csv(result: RunResult) -> str:
    """One row per detection, sorted by range then velocity; the last column ``label`` says
    what the simulation put there (:func:`rtsgeom.pipeline.run.label_detections`); ``elevation_deg``
    (0 for an azimuth-only array) sits after ``snr_db``, so the earlier columns keep their
    places; ``angle_peak`` before ``label``: the direction's rank among its cell's angle peaks
    (0 the strongest; ``[radar] angle_peaks_max``)."""
    det = result.detections
    labels = label_detections(result)
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(["range_m", "velocity_mps", "angle_deg", "power_db", "snr_db", "elevation_deg",
                "angle_peak", "label"])
    order = np.lexsort((det.velocity_mps, det.range_m))
    el = det.elevation_deg
    for i in order:
        w.writerow([f"{det.range_m[i]:.4f}", f"{det.velocity_mps[i]:.4f}",
                    f"{det.angle_deg[i]:.4f}", f"{det.power_db[i]:.2f}", f"{det.snr_db[i]:.2f}",
                    f"{el[i]:.4f}", int(det.peak_rank[i]), labels[i]])
    return buf.getvalue()


def figure_png(fig) -> bytes:
    """A figure as PNG bytes, in the style and resolution of
    :func:`rtsgeom.viz.figures.save_figure` (kept in memory: the report embeds exactly these)."""
    from ..viz.figures import print_png
    buf = io.BytesIO()
    print_png(fig, buf)
    return buf.getvalue()


#: the maps' arrays (:func:`map_arrays`) in their order, with units
MAP_UNITS = {"range_m": "m", "velocity_mps": "m/s", "doppler_hz": "Hz", "angle_deg": "deg",
             "range_doppler_db": "dB", "range_angle_db": "dB"}


def map_arrays(result: RunResult) -> dict[str, np.ndarray]:
    """The two maps of a run as plain arrays in dB, in the order of :data:`MAP_UNITS`: the
    axes ``range_m``, ``velocity_mps``, ``doppler_hz`` (of the Doppler axis), ``angle_deg``
    (-60..60 deg in 0.25 deg steps), ``range_doppler_db`` (range, velocity) and
    ``range_angle_db`` (range, angle; each range bin at its strongest Doppler bin). What the
    PNGs and ``maps.npz|mat`` are drawn from, without xarray (its import with pandas was a
    tenth of the main job); :func:`map_dataset` is the same as an ``xarray.Dataset``."""
    rd = result.rd
    angle = np.arange(-60.0, 60.0 + 1e-9, 0.25)  # as RangeDoppler.range_angle_to_xarray
    return {"range_m": rd.range_m, "velocity_mps": rd.velocity_mps,
            "doppler_hz": rd.doppler_hz, "angle_deg": angle,
            "range_doppler_db": _to_db(rd.power),
            "range_angle_db": _to_db(range_angle_map(rd, result.cube, np.radians(angle)))}


def _to_db(power):  # as RangeDoppler.power_db
    return 10 * np.log10(np.maximum(power, 1e-30))


def map_dataset(result: RunResult, arrays: dict | None = None):
    """The two maps of a run as one ``xarray.Dataset``, in dB: ``range_doppler_db`` (dims
    ``range_m``, ``velocity_mps``; ``doppler_hz`` a second coordinate on the Doppler axis) and
    ``range_angle_db`` (dims ``range_m``, ``angle_deg``, -60..60 deg in 0.25 deg steps), the
    arrays of :func:`map_arrays` (``arrays``: those, computed when not given). Every variable
    and coordinate carries ``units``; ``maps.nc`` is written from this."""
    import xarray as xr
    a = map_arrays(result) if arrays is None else arrays
    rdm = xr.DataArray(a["range_doppler_db"], dims=("range_m", "velocity_mps"),
                       coords={"range_m": a["range_m"], "velocity_mps": a["velocity_mps"],
                               "doppler_hz": ("velocity_mps", a["doppler_hz"])},
                       attrs={"units": "dB", "long_name": "range-Doppler power, sum over "
                                                         "virtual channels of |X|^2"})
    ram = xr.DataArray(a["range_angle_db"], dims=("range_m", "angle_deg"),
                       coords={"range_m": a["range_m"], "angle_deg": a["angle_deg"]},
                       attrs={"units": "dB", "long_name": "beamformer power, each range bin "
                                                         "at its strongest Doppler bin"})
    ds = xr.Dataset({"range_doppler_db": rdm, "range_angle_db": ram},
                    attrs={"scene": result.scene.name, "source": "rtsgeom run"})
    for name in ("range_m", "velocity_mps", "doppler_hz", "angle_deg"):
        ds[name].attrs["units"] = MAP_UNITS[name]
    return ds


def _plain(maps) -> dict[str, np.ndarray]:
    """:func:`map_arrays`' dict of a :func:`map_dataset` (or that dict itself)."""
    if isinstance(maps, dict):
        return maps
    return {k: np.asarray(maps[k].values) for k in MAP_UNITS}


def maps_arrays(ds, formats=MAP_FORMATS) -> dict[str, bytes]:
    """:func:`map_dataset` (or :func:`map_arrays`) as ``maps.npz`` (numpy), ``maps.mat``
    (MATLAB: the same variable names, axes as column vectors, a ``units`` struct) and
    ``maps.nc`` (NetCDF-3 via xarray's scipy engine: ``ds`` a dataset), as bytes by file
    name: those of ``formats`` only (each costs its writing time; all three were 2.1 s of a
    4.8 s run)."""
    arrays = _plain(ds)
    units = {k: MAP_UNITS[k] for k in arrays}
    out = {}
    if "npz" in formats:
        npz = io.BytesIO()
        np.savez(npz, **arrays, units=json.dumps(units))
        out["maps.npz"] = npz.getvalue()
    if "mat" in formats:
        import scipy.io
        mat = io.BytesIO()
        scipy.io.savemat(mat, {**arrays, "units": units}, oned_as="column")
        out["maps.mat"] = _without_timestamp(mat.getvalue())
    if "nc" in formats:
        if isinstance(ds, dict):
            raise ValueError("maps_arrays: maps.nc is written from map_dataset's dataset")
        out["maps.nc"] = ds.to_netcdf(engine="scipy")
    return out


MAT_DESCRIPTION = b"MATLAB 5.0 MAT-file, rtsgeom run maps"


def _without_timestamp(mat: bytes) -> bytes:
    """A MAT-file with its 116-byte header text fixed: scipy writes the creation time there,
    so two runs of one scene differed in ``maps.mat`` alone (the text is free-form; MATLAB
    reads the version and byte-order fields after it)."""
    return MAT_DESCRIPTION.ljust(116, b"\0") + mat[116:]


def render_maps(result: RunResult, ds=None) -> dict[str, bytes]:
    """Range-Doppler and range-angle maps as PNG bytes (paper Figs. "Range-Doppler map ..." and
    "Range angle detections ..."), by file name; ``ds``: :func:`map_arrays` or
    :func:`map_dataset` (computed when not given)."""
    from ..viz.figures import range_angle_figure, range_doppler_figure
    a = map_arrays(result) if ds is None else _plain(ds)
    rd, det, scene = result.rd, result.detections, result.scene
    f1 = range_doppler_figure(a["range_doppler_db"], rd.range_m, rd.velocity_mps,
                              detections=np.c_[det.range_m, det.velocity_mps],
                              title=f"{scene.name}: range-Doppler map"
                              + (f" (ADC CLIPPED: {result.cube.clipped} samples)"
                                 if result.cube.clipped else ""))
    sets = np.array([[t.range_m, np.degrees(t.angle_rad)] for t in scene.targets]).reshape(-1, 2)
    f2 = range_angle_figure(a["range_angle_db"], rd.range_m, a["angle_deg"],
                            detections=np.c_[det.range_m, det.angle_deg], set_points=sets,
                            title=f"{scene.name}: range-angle map")
    return {"range_doppler.png": figure_png(f1), "range_angle.png": figure_png(f2)}


def write_maps(result: RunResult, out: Path) -> list[Path]:
    """Write :func:`render_maps` into ``out``; return the paths."""
    paths = []
    for name, data in render_maps(result).items():
        write_bytes(out / name, data)
        paths.append(out / name)
    return paths


def _calibration_figures(result: RunResult) -> list[bytes]:
    """The calibration sweeps as PNG bytes: one pair's figure, or one figure of every pair's
    sweep as small multiples on common axes (``viz.sweeps``: 32 figures of a 64-front-end
    arc's pairs took 5 s of CPU and made the report 32 figures long; the one, 0.9 s)."""
    pairs = result.calibration.get("pairs", [])
    if not pairs:
        return []
    name = result.scene.name
    if len(pairs) == 1:
        return [_calibration_png(name, pairs[0])]
    from ..viz.sweeps import calibration_sweeps_figure
    return [figure_png(calibration_sweeps_figure(
        [_sweep_arrays(cal) for cal in pairs],
        title=f"{name}: phase coherency calibration of the {len(pairs)} front-end pairs"))]


def _sweep_arrays(cal: dict) -> dict:
    """A calibration record's (``to_dict``) sweep as arrays, by the names the figures take."""
    rf = cal.get("refinement", [])

    def err(points):
        return np.array([np.nan if p["angle_error_deg"] is None else p["angle_error_deg"]
                         for p in points], float)
    return {"label": f"{cal['pair'][0]}-{cal['pair'][1]}",
            "delta_tau_s": np.array([p["delta_tau_s"] for p in cal["sweep"]], float),
            "angle_error_deg": err(cal["sweep"]),
            "chosen_delta_tau_s": cal["delta_tau_s"], "period_s": cal["period_s"],
            "residual_error_deg": cal.get("residual_error_deg"),
            "refine_delta_tau_s": [p["delta_tau_s"] for p in rf], "refine_error_deg": err(rf)}


def _calibration_png(scene_name: str, cal: dict) -> bytes:
    """One pair's calibration sweep (a calibration record's ``to_dict``) as PNG bytes."""
    from ..viz.figures import calibration_sweep_figure
    a = _sweep_arrays(cal)
    fig = calibration_sweep_figure(
        a["delta_tau_s"], a["angle_error_deg"], a["chosen_delta_tau_s"], a["period_s"],
        residual_error_deg=a["residual_error_deg"],
        refine_delta_tau_s=a["refine_delta_tau_s"], refine_error_deg=a["refine_error_deg"],
        title=f"{scene_name}: phase coherency calibration, front ends {a['label']}")
    return figure_png(fig)


def targets_table(matches: list[dict]) -> dict:
    """The report's set-point vs detection table; with elevation columns when a target has
    an elevation (a 2-D cell scene: ``set`` carries ``elevation_deg``)."""
    el = any("elevation_deg" in m["set"] for m in matches)
    keys = [("range_m", "range (m)", 4), ("velocity_mps", "velocity (m/s)", 4),
            ("angle_deg", "angle (deg)", 3)] + ([("elevation_deg", "elevation (deg)", 3)]
                                                 if el else [])
    rows = []
    for m in matches:
        s, d, e = m["set"], m["detection"], m["error"]
        found = (("not detected",) + ("-",) * (2 * len(keys) - 1) if d is None else
                 tuple(d.get(k, "-") for k, _, _ in keys) + tuple(e.get(k, "-")
                                                                  for k, _, _ in keys))
        rows.append([m["index"], *(s.get(k, 0.0) for k, _, _ in keys), *found])
    digits = [d for _, _, d in keys]
    return {"columns": ["target", *(f"set {name}" for _, name, _ in keys),
                        *(name for _, name, _ in keys),
                        *(name.replace(" (", " error (") for _, name, _ in keys)],
            "rows": rows, "digits": [None] + digits * 3}


def run_report_html(result: RunResult, maps: dict[str, bytes], paths_method: str,
                    warnings: list[str], setup_view: Forked | None = None,
                    calibration_figures: Forked | None = None) -> str:
    """``report.html`` of a run: scene summary, 3D view, figures, detections vs set-points,
    calibration, warnings; self-contained. Every image is bytes this run produced (``maps``
    from :func:`render_maps`; the 3D view from ``setup_view``, :func:`start_setup_view`, where
    given for exact paths, else rendered here; the calibration's from
    ``calibration_figures``, a ``fork_call`` of ``_calibration_figures``, where given, else
    drawn here), never a file read back from the output folder."""
    from ..viz.report import render_report
    sections = []
    images = []
    try:
        images.append(setup_view.result() if setup_view is not None and paths_method == "exact"
                      else setup_png(result.setup, result.paths, paths_method))
    except (ImportError, RuntimeError) as exc:  # no pyvista, no off-screen OpenGL (VizError),
        # no ray tracing for the drawn paths (RaytraceUnavailable): the report has the rest
        warnings = warnings + [f"3D view not rendered: {exc}"]
    sections.append({"heading": "Setup", "images": images,
                     "text": f"Paths: {paths_method} ({len(result.paths)} rows)."})
    sections.append({"heading": "Targets: set-points and detections",
                     "table": targets_table(result.matches),
                     "images": list(maps.values())})
    cal = result.calibration
    if cal:
        rows = [[f"{p['pair'][0]}-{p['pair'][1]}", p["delta_tau_s"] * 1e12,
                 p["residual_error_deg"], p["range_offset_m"] * 1e3] for p in cal["pairs"]]
        sections.append({
            "heading": "Calibration",
            "text": (f"Amplitude mode {cal['mode']}. Front ends alone are detected at "
                     + ", ".join(f"{a:.3f}" for a in cal["front_end_angles_deg"])
                     + " deg; gain corrections "
                     + ", ".join(f"{g:.4f}" for g in cal["gain_correction"]) + "."),
            "table": {"columns": ["front-end pair", "delay offset (ps)",
                                  "residual angle error (deg)", "range offset (mm)"],
                      "rows": rows, "digits": [None, 1, 4, 2]},
            "images": (calibration_figures.result() if calibration_figures is not None
                       else _calibration_figures(result))})
    det = result.detections
    labels = label_detections(result)
    sections.append({"heading": "All detections",
                     "table": {"columns": ["range (m)", "velocity (m/s)", "angle (deg)",
                                           "power (dB)", "SNR (dB)", "what it is"],
                               "rows": [[a, b, c, d, e, lab] for a, b, c, d, e, lab in
                                        zip(det.range_m, det.velocity_mps, det.angle_deg,
                                            det.power_db, det.snr_db, labels)],
                               "digits": [3, 3, 3, 1, 1, None]}})
    if warnings:
        sections.append({"heading": "Warnings", "warnings": warnings})
    return render_report(f"rtsgeom run: {result.scene.name}", scene_info(result.setup), sections)


def write_run(result: RunResult, folder: str | Path, paths_method: str = "exact",
              maps=("npz",), report: bool = True, warnings=(),
              setup_view: Forked | None = None) -> list[str]:
    """The output folder of ``rtsgeom run`` for ``result``.

    Parameters
    ----------
    result : RunResult
    folder : path
        An existing folder (``rtsgeom run`` writes into a staging folder swapped in whole).
    paths_method : str
        How the paths were computed (the summary and the report say it).
    maps : sequence of str
        The maps' array formats, a subset of :data:`MAP_FORMATS`.
    report : bool
        Also write report.html (3D view, figures).
    warnings : sequence of str
        The scene's warnings for the report (the run's own are added).
    setup_view : Forked, optional
        The report's 3D view started before the run (:func:`start_setup_view`).

    Returns
    -------
    list of str
        The names written: detections.csv, summary.json, the map PNGs and arrays,
        report.html.
    """
    folder = Path(folder)
    # the report's calibration figures depend on the calibration alone: drawn in a process
    # forked now, beside the maps (a 64-front-end arc's 32 pairs: 0.9 s of CPU)
    cal_figures = (fork_call(_calibration_figures, result)
                   if report and (result.calibration or {}).get("pairs") else None)
    write_text(folder / "detections.csv", detections_csv(result))
    write_json(folder / "summary.json", summary(result, paths_method))
    arrays = map_arrays(result)
    pngs = render_maps(result, arrays)
    files = {**pngs, **maps_arrays(map_dataset(result, arrays) if "nc" in maps else arrays,
                                   tuple(maps))}
    for name, data in files.items():
        write_bytes(folder / name, data)
    names = ["detections.csv", "summary.json", *files]
    if report:
        write_text(folder / "report.html",
                   run_report_html(result, pngs, paths_method,
                                   list(warnings) + list(result.warnings), setup_view,
                                   cal_figures))
        names.append("report.html")
    return names
