"""Cross-check of the ray tracer against closed-form geometry (``raytrace_paths`` vs exact models).

Three references, all float64:

* **Line of sight** — every ray-traced LoS row against :func:`~rtsgeom.paths.exact.exact_paths`:
  delay difference (ps), phase difference of ``gain * exp(-j 2 pi f tau)`` at the radar's centre
  frequency (deg) and gain difference (dB).
* **Faceted image method** — every single-bounce ``rut_to_rut`` sheet row against the mirror
  image of its Tx element in the plane of the triangle the ray tracer hit: the exact length of
  that reflection on this mesh. Also the number of facets that have a specular point of their own
  (exact geometric optics on the mesh) against the number of rows found.
* **Smooth cylinder** — the stationary points of ``|a - p| + |p - b|`` over ``p`` on the inner
  cylinder face (radius ``R_sheet``), i.e. the specular points of the true curved sheet, and the
  path length at each row's hit azimuth. The RuT sits on the sheet's axis: there the path length
  hardly varies over the whole sheet (a caustic, exactly constant on the axis), so the "specular
  point" is degenerate; for the AWR1843BOOST elements, 5 to 13 mm off the axis, the only stationary
  points lie at +-90 deg, off the sheet. The report says so instead of matching a point that does
  not exist.
* **Amplitude** — the coherent sum of a pair's sheet rows against a physical-optics (PO) integral
  over the smooth sheet (perfect conductor, cutouts removed): geometric optics on a faceted
  cylinder seen from near its axis returns one glint per facet, so its sum depends on the mesh.

``python -m rtsgeom.paths.crosscheck scenes/diewald2022.toml`` prints the report.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.constants import c
from scipy.optimize import brentq

from ..geometry import Setup
from .exact import exact_paths
from .table import RUT_TO_RUT, TX_TO_FE, Paths
from ..geometry import build_setup
from ..scene import load_scene

__all__ = ["crosscheck", "format_crosscheck", "smooth_path_length", "stationary_points",
           "facet_image_length", "po_sheet_response"]


def _wrap_deg(x):
    return (np.asarray(x) + 180.0) % 360.0 - 180.0


def _stats(values) -> dict:
    v = np.asarray(values, float)
    if v.size == 0:
        return {"n": 0, "max_abs": None, "rms": None, "mean": None}
    return {"n": int(v.size), "max_abs": float(np.max(np.abs(v))),
            "rms": float(np.sqrt(np.mean(v ** 2))), "mean": float(np.mean(v))}


# ------------------------------------------------------------------------------------------
# Geometry references
# ------------------------------------------------------------------------------------------


def smooth_path_length(a, b, centre, radius: float, az) -> np.ndarray:
    """Shortest ``|a - p| + |p - b|`` over the vertical line of the cylinder (axis through
    ``centre``, along z) at azimuth ``az`` (from +y towards +x). Unfolding in z:
    ``sqrt((h_a + h_b)^2 + (z_a - z_b)^2)`` with ``h`` the horizontal distances."""
    az = np.asarray(az, float)
    a, b, centre = (np.asarray(v, float) for v in (a, b, centre))
    p = centre[:2] + radius * np.stack([np.sin(az), np.cos(az)], -1)
    ha = np.linalg.norm(p - a[:2], axis=-1)
    hb = np.linalg.norm(p - b[:2], axis=-1)
    return np.hypot(ha + hb, a[2] - b[2])


def _smooth_z(a, b, centre, radius, az):
    """Height of the specular point on the vertical line at ``az`` (unfolded straight line)."""
    a, b, centre = (np.asarray(v, float) for v in (a, b, centre))
    p = centre[:2] + radius * np.array([np.sin(az), np.cos(az)])
    ha, hb = np.linalg.norm(p - a[:2]), np.linalg.norm(p - b[:2])
    return a[2] + (b[2] - a[2]) * ha / max(ha + hb, 1e-300)


def stationary_points(a, b, centre, radius: float, n_grid: int = 7201) -> dict:
    """Specular points of a reflection a -> cylinder -> b: the azimuths where the path length
    ``smooth_path_length`` is stationary. ``degenerate`` is True when it is constant over the
    whole circle (both points on the axis: every point of the cylinder reflects back)."""
    az = np.linspace(-np.pi, np.pi, n_grid)
    length = smooth_path_length(a, b, centre, radius, az)
    if np.ptp(length) < 1e-9:
        return {"degenerate": True, "azimuth_rad": np.zeros(0), "length_m": np.zeros(0)}
    h = 1e-6

    def deriv(x):
        return ((smooth_path_length(a, b, centre, radius, x + h)
                 - smooth_path_length(a, b, centre, radius, x - h)) / (2 * h))

    d = deriv(az)
    roots = []
    for i in np.flatnonzero(np.sign(d[:-1]) * np.sign(d[1:]) <= 0):
        lo, hi = az[i], az[i + 1]
        if d[i] == 0:
            roots.append(lo)
            continue
        if np.sign(deriv(lo)) == np.sign(deriv(hi)):
            continue
        roots.append(brentq(deriv, lo, hi, xtol=1e-13))
    roots = np.unique(np.round(np.asarray(roots, float), 10))
    return {"degenerate": False, "azimuth_rad": roots,
            "length_m": smooth_path_length(a, b, centre, radius, roots)}


def facet_image_length(a, b, triangle) -> tuple[float, bool]:
    """Exact single-reflection length a -> plane of ``triangle`` -> b (image method), and
    whether the specular point lies inside the triangle."""
    a, b, tri = (np.asarray(v, float) for v in (a, b, triangle))
    n = np.cross(tri[1] - tri[0], tri[2] - tri[0])
    n /= np.linalg.norm(n)
    img = a - 2.0 * np.dot(a - tri[0], n) * n
    d = b - img
    length = float(np.linalg.norm(d))
    denom = np.dot(d, n)
    if abs(denom) < 1e-15 or np.dot(a - tri[0], n) * np.dot(b - tri[0], n) <= 0:
        return length, False
    t = np.dot(tri[0] - img, n) / denom
    p = img + t * d
    v0, v1, v2 = tri[1] - tri[0], tri[2] - tri[0], p - tri[0]
    d00, d01, d11 = v0 @ v0, v0 @ v1, v1 @ v1
    d20, d21 = v2 @ v0, v2 @ v1
    den = d00 * d11 - d01 * d01
    u = (d11 * d20 - d01 * d21) / den
    w = (d00 * d21 - d01 * d20) / den
    eps = 1e-9
    return length, bool(u >= -eps and w >= -eps and u + w <= 1 + eps and 0 < t < 1)


def _inner_faces(setup: Setup) -> np.ndarray:
    """Indices of the sheet's triangles on its inner (concave) face."""
    mesh = setup.sheet
    cfg = setup.scene.sheet
    r0 = setup.fe.arc_radius_m + cfg.radius_offset_m
    ctr = mesh.triangles_center - setup.fe.arc_centre
    rr = np.hypot(ctr[:, 0], ctr[:, 1])
    radial = np.abs((mesh.face_normals[:, 0] * ctr[:, 0] + mesh.face_normals[:, 1] * ctr[:, 1])
                    / np.maximum(rr, 1e-12)) > 0.99
    return np.flatnonzero(radial & (rr < r0 + 0.5 * cfg.thickness_m))


def _on_sheet(setup: Setup, az: float, z: float) -> bool:
    cfg = setup.scene.sheet
    r0 = setup.fe.arc_radius_m + cfg.radius_offset_m
    zc = setup.fe.arc_centre[2]
    if not (cfg.angle_min_rad <= az <= cfg.angle_max_rad) or abs(z - zc) > 0.5 * cfg.height_m:
        return False
    for th in setup.fe.angle_rad:
        if (r0 * np.sin(az - th)) ** 2 + (z - zc) ** 2 < (0.5 * cfg.cutout_diameter_m) ** 2:
            return False
    return True


def po_sheet_response(setup: Setup, a, b, freq_hz: float, step_m: float | None = None) -> complex:
    """Physical-optics echo a -> smooth sheet -> b as a path response ``sum g exp(-j 2 pi f tau)``.

    Scalar PO of a perfect conductor (Gamma = -1, times the absorber's amplitude factor
    ``10^(-sheet.reflection_loss_db / 20)``) over the inner cylinder face, cutouts removed::

        u(b) = (j k / 2 pi) Gamma  INT exp(-j k (r1 + r2)) / (r1 r2) cos(theta_i) dS

    (for an infinite plane this is the image source ``Gamma exp(-j k L) / L``), returned as
    ``lambda / (4 pi) u(b)`` so that a line-of-sight path of length d gives ``lambda/(4 pi d)``.
    """
    cfg = setup.scene.sheet
    lam = c / freq_hz
    k = 2 * np.pi / lam
    r0 = setup.fe.arc_radius_m + cfg.radius_offset_m
    centre = np.asarray(setup.fe.arc_centre, float)
    step = step_m or lam / 8
    n_az = max(int(np.ceil((cfg.angle_max_rad - cfg.angle_min_rad) * r0 / step)), 2)
    n_z = max(int(np.ceil(cfg.height_m / step)), 2)
    # midpoint rule
    daz = (cfg.angle_max_rad - cfg.angle_min_rad) / n_az
    dz = cfg.height_m / n_z
    az = cfg.angle_min_rad + (np.arange(n_az) + 0.5) * daz
    z = -0.5 * cfg.height_m + (np.arange(n_z) + 0.5) * dz
    a, b = np.asarray(a, float), np.asarray(b, float)
    total = 0j
    for zi in np.array_split(z, max(1, n_z // 64)):
        AZ, Z = np.meshgrid(az, zi, indexing="ij")
        rhat = np.stack([np.sin(AZ), np.cos(AZ), np.zeros_like(AZ)], -1)
        p = centre + r0 * rhat + Z[..., None] * np.array([0.0, 0.0, 1.0])
        va, vb = a - p, b - p
        r1, r2 = np.linalg.norm(va, axis=-1), np.linalg.norm(vb, axis=-1)
        cos_i = np.clip(-(rhat * va).sum(-1) / r1, 0.0, 1.0)  # inner normal is -rhat
        mask = np.ones(AZ.shape, bool)
        for th in setup.fe.angle_rad:
            mask &= (r0 * np.sin(AZ - th)) ** 2 + Z ** 2 >= (0.5 * cfg.cutout_diameter_m) ** 2
        integrand = np.exp(-1j * k * (r1 + r2)) / (r1 * r2) * cos_i * mask
        total += integrand.sum() * r0 * daz * dz
    gamma = -(10.0 ** (-cfg.reflection_loss_db / 20.0))
    u = (1j * k / (2 * np.pi)) * gamma * total
    return complex(lam / (4 * np.pi) * u)


# ------------------------------------------------------------------------------------------
# The cross-check
# ------------------------------------------------------------------------------------------


def crosscheck(setup: Setup, rt_paths=None, po: bool = True) -> dict:
    """Compare ray-traced paths with the exact LoS model and the sheet's reflection geometry.

    ``rt_paths``: a :class:`~rtsgeom.paths.raytrace.RaytraceResult` (preferred: its hit
    triangles allow the per-facet check), a :class:`Paths` table (rows are then matched to the
    nearest faceted glint by delay), or None to ray-trace the scene now. Returns a JSON-ready
    dict (delays in ps, phases in deg, levels in dB).
    """
    details = None
    if rt_paths is None:
        from .raytrace import trace
        details = trace(setup)
        paths = details.paths
    elif isinstance(rt_paths, Paths):
        paths = rt_paths
    else:
        details, paths = rt_paths, rt_paths.paths
    freq = c / setup.rut.wavelength_m
    out: dict = {"frequency_hz": freq, "rows": len(paths), "method": paths.method}
    if details is not None:
        out["variant"] = details.variant
        out["raytrace_stats"] = details.stats
        out["timings_s"] = details.timings_s
    out["los"] = _check_los(setup, paths, freq)
    if setup.sheet is not None:
        out["sheet"] = _check_sheet(setup, paths, details, freq, po)
    return out


def _check_los(setup: Setup, paths: Paths, freq: float) -> dict:
    ex = exact_paths(setup)
    d_ps, d_deg, d_db, missing = [], [], [], []
    for i in range(len(ex)):
        q, dr = int(ex.front_end[i]), int(ex.direction[i])
        el = int(ex.rut_tx[i] if dr == TX_TO_FE else ex.rut_rx[i])
        col = paths.rut_tx if dr == TX_TO_FE else paths.rut_rx
        m = ((paths.front_end == q) & (paths.direction == dr) & (col == el)
             & (paths.bounces == 0))
        name = f"{'tx_to_fe' if dr == TX_TO_FE else 'fe_to_rx'} fe{q} {'tx' if dr == TX_TO_FE else 'rx'}{el}"
        if not np.any(m):
            missing.append(name)
            continue
        j = np.flatnonzero(m)[0]
        d_ps.append((paths.delay_s[j] - ex.delay_s[i]) * 1e12)
        h_rt = paths.gain[j] * np.exp(-2j * np.pi * freq * paths.delay_s[j])
        h_ex = ex.gain[i] * np.exp(-2j * np.pi * freq * ex.delay_s[i])
        d_deg.append(float(np.degrees(np.angle(h_rt / h_ex))))
        d_db.append(20 * np.log10(abs(paths.gain[j]) / abs(ex.gain[i])))
    return {"delay_ps": _stats(d_ps), "phase_deg": _stats(d_deg), "gain_db": _stats(d_db),
            "missing": missing}


@dataclass(frozen=True)
class _SheetCheck:
    """What every element pair's sheet check reads: the ray-traced rows, the smooth cylinder
    (radius ``r0`` about ``centre``), the mesh's inner triangles and the single-bounce rows."""

    setup: Setup
    paths: Paths
    details: object
    freq: float
    po: bool
    r0: float
    centre: np.ndarray
    inner: np.ndarray
    single: np.ndarray


def _facet_delays(ck: _SheetCheck, a, b, rows) -> tuple[np.ndarray, list, int]:
    """Exact geometric optics on the mesh for the pair (a, b): the distinct glint lengths (every
    inner triangle with its own specular point; the two triangles of a planar quad merged), each
    row's delay against its own facet's (ps) and how many rows hit outside their triangle."""
    tris, paths, details = ck.setup.sheet.triangles, ck.paths, ck.details
    glints = {}
    for f in ck.inner:
        length, inside = facet_image_length(a, b, tris[f])
        if inside:
            glints[int(f)] = length
    g_len = np.unique(np.round(np.array(sorted(glints.values())), 12))
    facet_ps, outside = [], 0
    for j in rows:
        if details is not None:
            length, inside = facet_image_length(a, b, tris[int(details.primitives[j, 0])])
            outside += not inside
        else:
            if g_len.size == 0:
                continue
            length = g_len[np.argmin(np.abs(g_len - paths.delay_s[j] * c))]
        facet_ps.append((paths.delay_s[j] - length / c) * 1e12)
    return g_len, facet_ps, outside


def _smooth_points(ck: _SheetCheck, a, b) -> tuple[list, dict]:
    """The smooth cylinder's stationary points for the pair (a, b), each with its azimuth,
    height, delay and whether it lies on the sheet."""
    sp = stationary_points(a, b, ck.centre, ck.r0)
    spts = []
    for az, length in zip(sp["azimuth_rad"], sp["length_m"]):
        z = _smooth_z(a, b, ck.centre, ck.r0, az)
        spts.append({"azimuth_deg": float(np.degrees(az)), "z_m": float(z),
                     "delay_ns": float(length / c * 1e9),
                     "on_sheet": _on_sheet(ck.setup, az, z)})
    return spts, sp


def _rows_vs_smooth(ck: _SheetCheck, a, b, rows, spts, entry) -> list:
    """The rows' delay span, their delay against the smooth cylinder at their hit point (ps,
    returned), and the row nearest the smooth specular delay, added to ``entry``."""
    paths, details = ck.paths, ck.details
    entry["rt_delay_span_ns"] = [float(paths.delay_s[rows].min() * 1e9),
                                 float(paths.delay_s[rows].max() * 1e9)]
    sm = []
    if details is not None:
        hit = details.vertices[rows, 0] - ck.centre
        az_hit = np.arctan2(hit[:, 0], hit[:, 1])
        sm = (paths.delay_s[rows] - smooth_path_length(a, b, ck.centre, ck.r0, az_hit) / c) * 1e12
        entry["delay_vs_smooth_at_hit_ps"] = _stats(sm)
    on = [s for s in spts if s["on_sheet"]]
    if on:
        best = min(on, key=lambda s: abs(s["delay_ns"] * 1e-9 - paths.delay_s[rows]).min())
        entry["nearest_row_to_specular_ps"] = float(
            np.min(np.abs(paths.delay_s[rows] - best["delay_ns"] * 1e-9)) * 1e12)
    return list(sm)


def _levels(ck: _SheetCheck, a, b, rows, entry) -> None:
    """The rows' coherent sum, one smooth glint's level and (``po``) physical optics on the
    mesh, in dB, added to ``entry``."""
    paths, freq = ck.paths, ck.freq
    h_rt = np.sum(paths.gain[rows] * np.exp(-2j * np.pi * freq * paths.delay_s[rows]))
    entry["rt_coherent_db"] = float(20 * np.log10(max(abs(h_rt), 1e-300)))
    entry["single_glint_db"] = float(20 * np.log10(c / freq / (4 * np.pi * 2 * ck.r0)))
    if ck.po:
        h_po = po_sheet_response(ck.setup, a, b, freq)
        entry["po_db"] = float(20 * np.log10(abs(h_po)))
        entry["rt_minus_po_db"] = entry["rt_coherent_db"] - entry["po_db"]
        entry["rt_minus_po_phase_deg"] = float(np.degrees(np.angle(h_rt / h_po))) \
            if abs(h_rt) > 0 else None


def _sheet_pair(ck: _SheetCheck, m: int, k: int) -> tuple[dict, list, list, int]:
    """One (RuT Tx m, RuT Rx k) pair's sheet echo against the faceted and the smooth model:
    its entry, its delays against the own facet and the smooth cylinder (ps), rows outside."""
    rut, cfg = ck.setup.rut, ck.setup.scene.sheet
    a, b = rut.tx_world[m], rut.rx_world[k]
    rows = np.flatnonzero(ck.single & (ck.paths.rut_tx == m) & (ck.paths.rut_rx == k))
    g_len, facet_ps, outside = _facet_delays(ck, a, b, rows)
    spts, sp = _smooth_points(ck, a, b)
    grid = np.linspace(cfg.angle_min_rad, cfg.angle_max_rad, 2001)
    lengths = smooth_path_length(a, b, ck.centre, ck.r0, grid)
    entry = {"tx": m, "rx": k, "rows": int(rows.size),
             "faceted_go_glints": int(g_len.size),
             "rows_outside_their_triangle": outside,
             "delay_vs_own_facet_ps": _stats(facet_ps),
             "stationary_points": spts,
             "degenerate": sp["degenerate"],
             "smooth_delay_span_on_sheet_ns": [float(lengths.min() / c * 1e9),
                                               float(lengths.max() / c * 1e9)]}
    smooth = _rows_vs_smooth(ck, a, b, rows, spts, entry) if rows.size else []
    _levels(ck, a, b, rows, entry)
    return entry, facet_ps, smooth, outside


def _check_sheet(setup: Setup, paths: Paths, details, freq: float, po: bool) -> dict:
    rut, fe = setup.rut, setup.fe
    r0 = fe.arc_radius_m + setup.scene.sheet.radius_offset_m
    centre = np.asarray(fe.arc_centre, float)
    inner = _inner_faces(setup)
    sagitta_ps = None
    if inner.size:  # facet width -> bias of a flat facet's centre against the smooth cylinder
        v = setup.sheet.triangles[inner] - centre
        az_v = np.arctan2(v[..., 0], v[..., 1])
        daz = float(np.max(np.ptp(az_v, axis=1)))  # a planar triangle spans one facet at most
        sagitta_ps = -2 * r0 * (1 - np.cos(daz / 2)) / c * 1e12
    single = (paths.direction == RUT_TO_RUT) & (paths.bounces == 1)
    if details is not None:
        single &= details.objects[:, 0] == "sheet"
    ck = _SheetCheck(setup, paths, details, freq, po, r0, centre, inner, single)
    pairs, all_facet, all_smooth = [], [], []
    outside_total = 0
    for m in range(rut.tx_world.shape[0]):
        for k in range(rut.rx_world.shape[0]):
            entry, facet_ps, smooth, outside = _sheet_pair(ck, m, k)
            pairs.append(entry)
            all_facet += facet_ps
            all_smooth += smooth
            outside_total += outside
    virtual = {(int(t), int(r)) for t, r in zip(rut.virtual_tx, rut.virtual_rx)}
    used = [p for p in pairs if (p["tx"], p["rx"]) in virtual]
    res = {
        "radius_m": r0,
        "two_r_over_c_ns": 2 * r0 / c * 1e9,
        "facet_sagitta_bias_ps": sagitta_ps,
        "rows": int(np.sum(single)),
        "rows_outside_their_triangle": outside_total,
        "delay_vs_own_facet_ps": _stats(all_facet),
        "delay_vs_smooth_at_hit_ps": _stats(all_smooth),
        "pairs_with_specular_point_on_sheet": sum(bool(any(s["on_sheet"] for s in p["stationary_points"]))
                                                  for p in pairs),
        "axis_is_degenerate": stationary_points(centre, centre, centre, r0)["degenerate"],
        "pairs": pairs,
    }
    if po and used:
        diff = np.array([p["rt_minus_po_db"] for p in used])
        res["rt_minus_po_db_virtual"] = {"min": float(diff.min()), "max": float(diff.max()),
                                         "mean": float(diff.mean())}
    return res


def format_crosscheck(r: dict) -> str:
    """Human-readable summary of :func:`crosscheck`."""
    def f(x, fmt="{:.4f}"):
        return "n/a" if x is None else fmt.format(x)

    lines = [f"cross-check at {r['frequency_hz'] / 1e9:.4f} GHz, {r['rows']} ray-traced rows"
             + (f", variant {r['variant']}" if "variant" in r else "")]
    lo = r["los"]
    lines.append(f"LoS ({lo['delay_ps']['n']} rows): delay max|d| {f(lo['delay_ps']['max_abs'])} ps, "
                 f"RMS {f(lo['delay_ps']['rms'])} ps; phase max|d| {f(lo['phase_deg']['max_abs'])} deg, "
                 f"RMS {f(lo['phase_deg']['rms'])} deg; gain max|d| {f(lo['gain_db']['max_abs'])} dB"
                 + (f"; MISSING {', '.join(lo['missing'])}" if lo["missing"] else ""))
    s = r.get("sheet")
    if s:
        fa, sm = s["delay_vs_own_facet_ps"], s["delay_vs_smooth_at_hit_ps"]
        lines.append(f"sheet single bounce ({s['rows']} rows, R = {s['radius_m']:g} m, 2R/c = "
                     f"{s['two_r_over_c_ns']:.6f} ns): delay vs own facet (image method) max|d| "
                     f"{f(fa['max_abs'])} ps, RMS {f(fa['rms'])} ps; "
                     f"rows outside their triangle (Sionna's 1 cm image tolerance): "
                     f"{s['rows_outside_their_triangle']}")
        lines.append(f"  vs smooth cylinder at the hit azimuth: mean {f(sm['mean'])} ps, max|d| "
                     f"{f(sm['max_abs'])} ps (flat-facet sagitta bias {f(s['facet_sagitta_bias_ps'])} ps)")
        lines.append(f"  element pairs with a specular point of the smooth cylinder on the sheet: "
                     f"{s['pairs_with_specular_point_on_sheet']} of {len(s['pairs'])}; the cylinder "
                     f"axis is {'degenerate (every point is specular)' if s['axis_is_degenerate'] else 'regular'}")
        for p in s["pairs"]:
            st = ", ".join(f"{q['azimuth_deg']:+.1f} deg{'' if q['on_sheet'] else ' (off sheet)'}"
                           for q in p["stationary_points"]) or "none"
            span = p.get("rt_delay_span_ns")
            lines.append(
                f"  tx{p['tx']}-rx{p['rx']}: {p['rows']} rows / {p['faceted_go_glints']} facet glints, "
                f"delay {('%.6f-%.6f ns' % tuple(span)) if span else 'n/a'} (smooth sheet "
                f"{p['smooth_delay_span_on_sheet_ns'][0]:.6f}-{p['smooth_delay_span_on_sheet_ns'][1]:.6f} ns), "
                f"stationary at {st}; coherent {p['rt_coherent_db']:.1f} dB"
                + (f", PO {p['po_db']:.1f} dB" if "po_db" in p else "")
                + f", one glint {p['single_glint_db']:.1f} dB")
        if "rt_minus_po_db_virtual" in s:
            d = s["rt_minus_po_db_virtual"]
            lines.append(f"  ray tracer minus PO over the virtual pairs: {d['min']:+.1f} .. "
                         f"{d['max']:+.1f} dB (mean {d['mean']:+.1f} dB)")
    return "\n".join(lines)


def main(argv=None) -> int:  # pragma: no cover - thin wrapper
    import argparse
    import json
    ap = argparse.ArgumentParser(prog="python -m rtsgeom.paths.crosscheck",
                                 description="ray tracer vs exact geometry")
    ap.add_argument("scene")
    ap.add_argument("--json", action="store_true")
    ap.add_argument("--no-po", action="store_true", help="skip the physical-optics integrals")
    args = ap.parse_args(argv)
    r = crosscheck(build_setup(load_scene(args.scene)), po=not args.no_po)
    print(json.dumps(r, indent=2) if args.json else format_crosscheck(r))
    return 0


if __name__ == "__main__":  # pragma: no cover
    raise SystemExit(main())
