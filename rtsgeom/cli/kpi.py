"""``rtsgeom kpi``: the setup's datasheet (``analysis.kpi``): ``kpi.json``, a self-contained
``kpi.html`` and ``kpi.pdf`` in ``--out``, checked against ``--spec``; exit 0 when every KPI
of the spec is met (or no spec), 1 when one is missed, 2 on bad input."""

from __future__ import annotations

from ..analysis.kpi import KpiStudy, load_spec
from ..analysis.kpi.study import DEFAULT_SIGMA_MM
from ..errors import AngleUnreachable, ParameterError, UsageError
from ._common import (declared_option, load_scene_checked, output_folder, output_path,
                      print_outputs, progress, scene_arg)


def cmd_kpi(args) -> int:
    from .._lib.io import write_bytes, write_json, write_text
    scene = load_scene_checked(args.scene)
    spec = None if args.spec is None else load_spec(args.spec)
    sigma = args.sigma_mm
    if sigma is not None and len(sigma) not in (1, 3):
        raise UsageError(f"--sigma-mm {' '.join(map(str, sigma))}: give one number (every "
                         "axis) or three (radial, tangential, height)")
    try:
        study = KpiStudy(sigma_mm=None if sigma is None else (sigma[0] if len(sigma) == 1
                                                              else tuple(sigma)),
                         sigma_phase_deg=args.sigma_phase_deg, points=args.points,
                         draws=args.draws, seed=args.seed, spec=spec)
    except ParameterError as exc:
        raise UsageError(str(exc)) from None
    with output_folder(args.out, [args.scene, args.spec]) as stage:
        with progress(args.quiet or args.json) as report:
            try:
                sheet = study(scene, progress=report)
            except AngleUnreachable as exc:
                raise UsageError(f"{args.scene}: {exc}") from None
        out = sheet.to_dict()
        if stage is not None:
            import io
            from ..analysis.kpi.report import figures, to_html, write_pdf
            figs = figures(sheet)
            write_json(stage / "kpi.json", out)
            write_text(stage / "kpi.html", to_html(sheet, figs))
            buf = io.BytesIO()
            write_pdf(sheet, buf, figs)
            write_bytes(stage / "kpi.pdf", buf.getvalue())
    return print_outputs(args, "kpi", out, summary, ("kpi.json", "kpi.html", "kpi.pdf"),
                         sheet.exit_code)


def summary(out: dict) -> str:
    """The datasheet's headline (:func:`~rtsgeom.analysis.kpi.headline.headline`) and the
    spec's verdicts, with margins."""
    from ..analysis.kpi.headline import headline
    lines = [f"{out['scene']}: datasheet"]
    lines += [f"  {name:<18} {value}" for name, value in headline(out)]
    if out["spec"]:
        lines.append("spec: " + ("PASS" if out["passed"] else "FAIL"))
        for c in out["spec"]:
            if c["pass"] is None:
                lines.append(f"  {c['kpi']:<22} no value: {c['note']}")
                continue
            lines.append(f"  {c['kpi']:<22} {'pass' if c['pass'] else 'FAIL'}  value "
                         f"{_num(c['value'])}, limit {_num(c['limit'])}, margin "
                         f"{_num(c['margin'])}")
    return "\n".join(lines)


def _num(v) -> str:
    if isinstance(v, list):
        return "[" + ", ".join(_num(x) for x in v) + "]"
    return f"{v:.4g}" if isinstance(v, float) else str(v)


def register(sub) -> None:
    p = sub.add_parser("kpi", help="the setup's datasheet: KPIs with an uncertainty budget, "
                                   "checked against a spec")
    scene_arg(p)
    p.add_argument("--spec", default=None, help="spec file (TOML, every key optional: "
                                                "docs/kpi.md); exit 1 when a KPI misses it")
    # the study's options made from its declared arguments (KpiStudy.ARGS): ranges and
    # defaults written once, in the study
    declared = KpiStudy.ARGS
    declared_option(p, "sigma_mm", declared["sigma_mm"], None, f"{DEFAULT_SIGMA_MM:g}",
                    nargs="+")
    declared_option(p, "sigma_phase_deg", declared["sigma_phase_deg"], None,
                    "the RMS of [radar.channels]' phases, else 0")
    declared_option(p, "points", declared["points"], KpiStudy.points)
    declared_option(p, "draws", declared["draws"], KpiStudy.draws)
    declared_option(p, "seed", declared["seed"], None, "the scene's seed")
    p.add_argument("--json", action="store_true", help="print the datasheet as JSON")
    p.add_argument("--out", type=output_path, default=None,
                   help="folder for kpi.json, kpi.html and kpi.pdf")
    p.add_argument("--quiet", action="store_true", help="no progress output")
    p.set_defaults(func=cmd_kpi)
