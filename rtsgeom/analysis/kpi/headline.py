"""The datasheet's headline: its key KPIs as (name, value) rows, made once from the JSON
(:meth:`~.study.Datasheet.to_dict`) and printed by every view: the command's summary
(``rtsgeom kpi``), the HTML's and the PDF's key figures (:mod:`.report`) and the
:class:`~.study.Datasheet`'s repr."""

from __future__ import annotations

__all__ = ["headline"]


def headline(d: dict) -> list[tuple[str, str]]:
    """The headline KPIs of a datasheet's JSON ``d`` as (name, value with its unit) rows.

    Parameters
    ----------
    d : dict
        ``Datasheet.to_dict()`` (or ``kpi.json`` read back).

    Returns
    -------
    list of (str, str)
        Field of view, angle accuracy, receiver noise, range, velocity, targets, ghosts and
        near field, in that order.
    """
    fov, rv, tg, gh = (d["field_of_view"], d["range_velocity"], d["targets"],
                       d["ghosts_leakage"])
    acc, inputs = d["angle_accuracy_summary"], d["inputs"]
    gaps = ", ".join(f"{a:.2f} .. {b:.2f}" for a, b in fov["gaps_deg"]) or "none"
    worst = acc["worst_accuracy_deg"]
    snr = inputs.get("snr_effective_db")
    snr_from = inputs.get("snr_from", "radar.snr_db")  # (a kpi.json written before it)
    return [
        ("field of view", f"{fov['azimuth_deg'][0]:.2f} .. {fov['azimuth_deg'][1]:.2f} deg "
                          f"({fov['mode']}), gaps: {gaps}"
         + (", elevation {:.2f} .. {:.2f} deg".format(*fov["elevation_deg"])
            if fov["cells"] else "")),
        ("angle accuracy", acc["note"] if worst is None else
         f"|error| + U (k = 2) worst {worst:.4f} deg; {acc['gum_validation']}"),
        ("receiver noise", "none: " + snr_from if snr is None else
         f"SNR {snr:.1f} dB at the detection cell ({snr_from})"),
        ("range", f"{rv['min_range_m']:.3f} .. {rv['max_range_m']:.2f} m, resolution "
                  f"{rv['range_resolution_m']:.4f} m, RTS step {rv['range_step_m'] * 1e3:.3f} "
                  "mm, accuracy " + ("- (no targets)" if rv["range_accuracy_m"] is None else
                                     f"{rv['range_accuracy_m']:.4g} m on the scene's targets")),
        ("velocity", f"+-{rv['max_velocity_mps']:.3f} m/s, resolution "
                     f"{rv['velocity_resolution_mps']:.4f} m/s, accuracy "
                     + ("-" if rv["velocity_accuracy_mps"] is None else
                        f"{rv['velocity_accuracy_mps']:.4g} m/s")),
        ("targets", f"{tg['per_channel']} per channel, {tg['total']} in total; "
                    + _resolution(tg["resolution"])),
        ("ghosts", f"strongest {gh['ghost_suppression_db']:.1f} dB below its target; RuT ADC "
                   "clip margin " + ("-" if tg.get("clip_margin_db") is None else
                                     f"{tg['clip_margin_db']:.1f} dB")),
        ("near field", f"Fraunhofer distance {d['near_field']['fraunhofer_distance_m']:.3f} m"),
    ]


def _resolution(res: dict) -> str:
    if res.get("rts_deg") is None:
        return "minimum separation: - (" + res["note"] + ")"
    truth = res.get("truth_deg")
    return (f"minimum separation {res['rts_deg']:g} deg on the RTS, "
            f"{'-' if truth is None else f'{truth:g}'} deg on real targets")
