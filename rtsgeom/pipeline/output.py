"""The output folder of ``rtsgeom run``: detections as CSV, the summary, the range-Doppler and
range-angle maps (PNG, and as arrays in ``maps.npz|mat|nc``) and the self-contained
``report.html``, each as bytes or text from one :class:`~rtsgeom.pipeline.run.RunResult`, and
:func:`write_run`, the whole folder (what ``run`` writes, callable from Python)."""

from __future__ import annotations

import csv
import io
import json
import tempfile
from pathlib import Path

import numpy as np

from .._lib.io import write_bytes, write_json, write_text
from ..paths import compute_paths
from .info import scene_info
from .run import RunResult, label_detections, summary

__all__ = ["detections_csv", "figure_png", "map_dataset", "maps_arrays", "MAP_FORMATS",
           "render_maps", "write_maps", "targets_table", "run_report_html",
           "write_run"]


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
    import matplotlib as mpl

    from ..viz.figures import DPI, STYLE
    buf = io.BytesIO()
    with mpl.rc_context(STYLE):
        fig.savefig(buf, format="png", dpi=DPI)
    return buf.getvalue()


def map_dataset(result: RunResult):
    """The two maps of a run as one ``xarray.Dataset``, in dB: ``range_doppler_db`` (dims
    ``range_m``, ``velocity_mps``; ``doppler_hz`` a second coordinate on the Doppler axis) and
    ``range_angle_db`` (dims ``range_m``, ``angle_deg``, -60..60 deg in 0.25 deg steps), from
    :meth:`RangeDoppler.to_xarray <rtsgeom.radar.processing.RangeDoppler.to_xarray>` and
    :meth:`~rtsgeom.radar.processing.RangeDoppler.range_angle_to_xarray`. Every variable and
    coordinate carries ``units``. The PNGs and ``maps.npz|mat|nc`` are drawn from this."""
    import xarray as xr
    rd = result.rd

    def to_db(da):  # as RangeDoppler.power_db
        return 10 * np.log10(np.maximum(da, 1e-30))
    rdm = to_db(rd.to_xarray()).assign_attrs(
        units="dB", long_name="range-Doppler power, sum over virtual channels of |X|^2")
    ram = to_db(rd.range_angle_to_xarray(result.cube)).assign_attrs(
        units="dB", long_name="beamformer power, each range bin at its strongest Doppler bin")
    ds = xr.Dataset({"range_doppler_db": rdm, "range_angle_db": ram},
                    attrs={"scene": result.scene.name, "source": "rtsgeom run"})
    for name, unit in (("range_m", "m"), ("velocity_mps", "m/s"), ("doppler_hz", "Hz"),
                       ("angle_deg", "deg")):
        ds[name].attrs["units"] = unit
    return ds


MAP_FORMATS = ("npz", "mat", "nc")  # what ``run --maps`` may write; npz by default


def maps_arrays(ds, formats=MAP_FORMATS) -> dict[str, bytes]:
    """:func:`map_dataset` as ``maps.npz`` (numpy), ``maps.mat`` (MATLAB: the same variable
    names, axes as column vectors, a ``units`` struct) and ``maps.nc`` (NetCDF-3 via xarray's
    scipy engine), as bytes by file name: those of ``formats`` only (each costs its writing
    time; all three were 2.1 s of a 4.8 s run)."""
    arrays = {k: np.asarray(v.values) for k, v in {**ds.coords, **ds.data_vars}.items()}
    units = {k: (ds[k].attrs["units"]) for k in arrays}
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
    "Range angle detections ..."), by file name; ``ds``: :func:`map_dataset` (computed when
    not given)."""
    from ..viz.figures import range_angle_figure, range_doppler_figure
    ds = map_dataset(result) if ds is None else ds
    rd, det, scene = result.rd, result.detections, result.scene
    f1 = range_doppler_figure(ds.range_doppler_db.values, rd.range_m, rd.velocity_mps,
                              detections=np.c_[det.range_m, det.velocity_mps],
                              title=f"{scene.name}: range-Doppler map"
                              + (f" (ADC CLIPPED: {result.cube.clipped} samples)"
                                 if result.cube.clipped else ""))
    sets = np.array([[t.range_m, np.degrees(t.angle_rad)] for t in scene.targets]).reshape(-1, 2)
    f2 = range_angle_figure(ds.range_angle_db.values, rd.range_m, ds.angle_deg.values,
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
    from ..viz.figures import calibration_sweep_figure
    out = []
    for cal in result.calibration.get("pairs", []):
        t = np.array([p["delta_tau_s"] for p in cal["sweep"]])
        e = np.array([np.nan if p["angle_error_deg"] is None else p["angle_error_deg"]
                      for p in cal["sweep"]])
        rf = cal.get("refinement", [])
        fig = calibration_sweep_figure(
            t, e, cal["delta_tau_s"], cal["period_s"],
            residual_error_deg=cal.get("residual_error_deg"),
            refine_delta_tau_s=[p["delta_tau_s"] for p in rf],
            refine_error_deg=[np.nan if p["angle_error_deg"] is None else p["angle_error_deg"]
                              for p in rf],
            title=f"{result.scene.name}: phase coherency calibration, front ends "
                  f"{cal['pair'][0]}-{cal['pair'][1]}")
        out.append(figure_png(fig))
    return out


def _setup_png(result: RunResult, paths_method: str) -> bytes:
    from ..viz.scene3d import render_setup_png
    paths = result.paths
    if paths_method != "exact":  # the view draws reflections through their hit points,
        # which the table alone does not carry
        paths = compute_paths(result.setup, paths_method, for_drawing=True)
    with tempfile.TemporaryDirectory(prefix="rtsgeom-3d-") as tmp:  # private to this run
        return render_setup_png(result.setup, Path(tmp) / "setup.png",
                                paths=paths).read_bytes()


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
                    warnings: list[str]) -> str:
    """``report.html`` of a run: scene summary, 3D view, figures, detections vs set-points,
    calibration, warnings; self-contained. Every image is bytes this run produced (``maps``
    from :func:`render_maps`), never a file read back from the output folder."""
    from ..viz.report import render_report
    sections = []
    images = []
    try:
        images.append(_setup_png(result, paths_method))
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
            "images": _calibration_figures(result)})
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
              maps=("npz",), report: bool = True, warnings=()) -> list[str]:
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

    Returns
    -------
    list of str
        The names written: detections.csv, summary.json, the map PNGs and arrays,
        report.html.
    """
    folder = Path(folder)
    write_text(folder / "detections.csv", detections_csv(result))
    write_json(folder / "summary.json", summary(result, paths_method))
    ds = map_dataset(result)
    pngs = render_maps(result, ds)
    files = {**pngs, **maps_arrays(ds, tuple(maps))}
    for name, data in files.items():
        write_bytes(folder / name, data)
    names = ["detections.csv", "summary.json", *files]
    if report:
        write_text(folder / "report.html",
                   run_report_html(result, pngs, paths_method,
                                   list(warnings) + list(result.warnings)))
        names.append("report.html")
    return names
