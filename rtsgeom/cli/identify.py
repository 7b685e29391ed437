"""``rtsgeom identify``: measure a built setup (each front end's mounting errors, each channel's
gain, phase and delay) from probe captures (``rtsgeom adc --active I``) with
:mod:`rtsgeom.identify`."""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

from ..errors import CaptureError, ParameterError, UsageError
from ..identify import identified_scene_toml, identify, read_capture
from ..identify.fit import RESIDUAL_LIMIT
from ..identify.identification import MAX_CAPTURES
from ._common import load_scene_checked, output_folder, output_path, print_json, scene_arg, steps


def _whys(fe: dict, ch: dict) -> list[tuple[str, str]]:
    """A front end's and its channel's (parameter, why not identifiable)."""
    return list(fe["not_identifiable"].items()) + list(ch["not_identifiable"].items())


def _kind(why: str) -> str:
    """A reason with its numbers taken out: two front ends' reasons of one kind (a Cramer-Rao
    std of 989 and 1e+03 deg) are one paragraph."""
    return re.sub(r"[-+]?\d[\d.]*(e[-+]?\d+)?", "#", why)


def _text(d: dict) -> str:
    """The human summary: per front end its estimates, "not identifiable" where fixed; the
    reasons once for all front ends (the first front end's wording), and under a front end
    only a reason of another kind than that one, so that the summary grows by a few lines per
    front end, not by the reasons' paragraphs."""
    lines = []

    def val(x, unit, digits=4):
        return "not identifiable" if x is None else f"{x['value']:+.{digits}f} +- {x['std']:.{digits}f} {unit}"

    common: dict = {}  # key -> (its reason's kind, the reason, the front end it is from)
    for fe, ch in zip(d["front_ends"], d["channels"]):
        for key, why in _whys(fe, ch):
            common.setdefault(key, (_kind(why), why, fe["index"]))
    for fe, ch in zip(d["front_ends"], d["channels"]):
        lines.append(f"front end {fe['index']} ({fe['captures']} capture(s), residual "
                     f"{fe['residual_rms']:.2f} x noise{', MISFIT' if fe.get('misfit') else ''}):")
        for key, unit in (("radial_offset_mm", "mm"), ("tangential_offset_mm", "mm"),
                          ("height_offset_mm", "mm"), ("yaw_offset_deg", "deg")):
            lines.append(f"  {key:22s} {val(fe[key], unit)}")
        lines.append(f"  {'channel delay_offset_s':22s} "
                     + ("not identifiable" if ch["delay_offset_s"] is None else
                        f"{ch['delay_offset_s']['value']:+.4g} +- {ch['delay_offset_s']['std']:.2g} s"))
        lines.append(f"  {'channel gain_db':22s} {val(ch['gain_db'], 'dB')}")
        lines.append(f"  {'channel phase_deg':22s} {val(ch['phase_deg'], 'deg', 3)}")
        for key, why in _whys(fe, ch):
            if _kind(why) != common[key][0]:  # only what differs from the shared reason
                lines.append(f"  why not {key}: {why}")
    if common:
        lines.append("why not identifiable (for every front end above; the numbers are the "
                     "named front end's, each one's with --json):")
        for key, (_, why, q) in common.items():
            lines.append(f"  {key} (front end {q}): {why}")
    r = d.get("radar_channels")
    if r is not None:
        ref = r["references"]
        lines.append(f"radar channels (reference Tx {ref['tx']}, Rx {ref['rx']}, front end "
                     f"{ref['front_end']}):")
        for side in ("tx", "rx"):
            for a, (g, p) in enumerate(zip(r[f"{side}_gain_db"], r[f"{side}_phase_deg"])):
                lines.append(f"  {side} {a}  gain {val(g, 'dB', 3)}, phase {val(p, 'deg', 3)}")
        for key, why in r["not_identifiable"].items():
            lines.append(f"  why not {key}: {why}")
    return "\n".join(lines)


def cmd_identify(args) -> int:
    if len(args.captures) > MAX_CAPTURES:
        raise UsageError(f"CAPTURE: {len(args.captures)} captures: must be at most "
                         f"{MAX_CAPTURES}")
    if args.reference_front_end is not None and not args.radar_channels:
        raise UsageError(f"--reference-front-end {args.reference_front_end}: only with "
                         "--radar-channels (it fixes the radar's phase ramp)")
    with output_folder(args.out, [args.scene, *args.captures]) as stage:
        scene = load_scene_checked(args.scene)
        from ..geometry import build_setup
        rut = build_setup(scene).rut
        shape = (scene.radar.chirps_per_tx, rut.num_virtual, scene.radar.samples_per_chirp)
        caps = (read_capture(p, shape) for p in args.captures)  # one cube in memory at a time
        with steps(args.quiet or args.json) as step:
            step(f"fitting {len(args.captures)} capture(s)")
            try:
                ident = identify(scene, caps, accept_misfit=args.accept_misfit,
                                 radar_channels=args.radar_channels,
                                 reference=args.reference_front_end)
            except (OSError, CaptureError, ParameterError) as exc:
                raise UsageError(f"CAPTURE: {exc}") from None
        for f in ident.fits:
            if f.misfit is not None:
                print(f"rtsgeom: warning: {f.misfit}; accepted (--accept-misfit), its "
                      "estimates are flagged misfit in the output", file=sys.stderr)
        d = ident.to_dict()
        if stage is not None:
            text = Path(args.scene).read_text(encoding="utf-8")
            (stage / "identified.toml").write_text(identified_scene_toml(text, ident),
                                                   encoding="utf-8")
            (stage / "identified.json").write_text(json.dumps(d, indent=2, allow_nan=False)
                                                   + "\n", encoding="utf-8")
    if args.json:
        print_json(d)
    elif not args.quiet:
        print(_text(d))
        if args.out is not None:
            print(f"wrote {args.out}/identified.toml (the scene as built) and identified.json")
    return 0


def register(sub) -> None:
    p = sub.add_parser("identify", help="estimate each front end's mounting errors and each "
                                        "channel's gain/phase/delay from probe captures")
    scene_arg(p)
    p.add_argument("captures", nargs="+", type=Path, metavar="CAPTURE",
                   help="probe captures (.bin or .npy with its .json sidecar, as rtsgeom adc "
                        "--active I writes them)")
    p.add_argument("--json", action="store_true", help="print the result as one JSON object")
    p.add_argument("--out", type=output_path, default=None,
                   help="folder for identified.toml (the corrected scene) and identified.json")
    p.add_argument("--quiet", action="store_true", help="print nothing but errors (--json still prints the estimates)")
    p.add_argument("--accept-misfit", action="store_true",
                   help="write the estimates of a fit whose residual exceeds "
                        f"{RESIDUAL_LIMIT:g} x noise (flagged misfit) instead of refusing them")
    p.add_argument("--radar-channels", action="store_true",
                   help="also estimate the radar's own per-antenna gain and phase errors, "
                        "jointly with every captured front end (a reference Tx, Rx and front "
                        "end fix what no capture can tell apart)")
    p.add_argument("--reference-front-end", type=int, default=None, metavar="Q",
                   help="with --radar-channels: the front end whose tangential offset (and "
                        "height) stays the scene's; the others are measured relative to it "
                        "(default: the first captured)")
    p.set_defaults(func=cmd_identify)


__all__ = ["cmd_identify", "register"]
