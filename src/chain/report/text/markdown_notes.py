"""The notes under ``summary.md``'s table: how Δ and the SSW are measured, what the
paper says about friction and dissipation, and what the SSW rows show. A note that
cites a number of the run takes it from ``summary.json``; a note without the number in
the summary leaves the sentence out."""

from __future__ import annotations

from collections.abc import Mapping

from chain.report.printed import number

#: The notes that hold for every run (no number of the run in them).
FIXED_NOTES = [
    "* Δ = TOF(crossed) − TOF(reference) between the two sensors; |Δ| is fitted. In a "
    "simulation the LSTW and RSTW points are mirror images and count twice, so their "
    "standard errors are about √2 too small.",
    "* The simulation (Eq. 1) has no track friction; the paper attributes the small "
    "difference between its measured and simulated Δ to friction lengthening the pulses, "
    "and the large measured SSW to bead rotation and friction. The mechanism study (3D "
    "beads with rotation and friction on LAMMPS, and the other candidates in the virtual "
    "apparatus) tests both; its verdict is above when this run has it.",
    "* The paper states that viscoelastic dissipation leaves Δ unchanged (Sec. V); the "
    "rows C(model) / C(conservative model) test that on this run.",
    "* SSW at a sensor: the largest residual against the self-similar template behind the "
    "crossed pulse (behind its trailing minimum, else from one τ behind its peak), with a "
    "systematic error (the template misfit on the rising edge) and a statistical one (3 σ "
    "of the smoothed noise); a value not above its error is an upper limit. 'Resolved' is "
    "stricter: a distinct bump above 2 × (misfit + 3 σ). The slopes are weighted "
    "proportional fits of every measurable point: ± statistical (scatter) ± systematic "
    "(values shifted by their systematic error).",
    "* Along the simulated chain (tables/ssw_track.csv, figures/ssw_spacetime, Fig. 5b) "
    "the SSW is 'separated' where maxima at 3 or more neighbouring contacts link at Eq. "
    "5's transit time for their own size (within a factor 2): one rule for every model "
    "and N. Its far-field size comes from the long chains (config long_chains), at the "
    "farthest contact before the main pulse reaches the free end. Contact k joins beads "
    "k and k+1.",
]


def notes(summary: Mapping) -> list[str]:
    """The notes of ``summary.md`` for the run's ``summary.json``, as Markdown list items."""
    return [*FIXED_NOTES, _ssw_note(summary), *_attenuation_notes(summary)]


def _ssw_note(summary: Mapping) -> str:
    """What the SSW rows show, and why; the long chains' SSW speeds from the summary."""
    return (
        "* What the SSW rows show, and why (tests/test_ssw_track.py, docs/analysis.md): at "
        "the sensors the SSW is a shoulder, so its value is mostly the template misfit; it "
        "is decided far from the collision point."
        + _speed_sentence(summary)
        + " Fitted only where it has settled (20 beads on), the SSW's speed over Eq. 5 is "
        "the main pulse's own (Eq. 5 is a long-wavelength approximation): an excess "
        "nearer the collision point is the SSW still growing over the first contacts. "
        "With Kuwabara-Kono dissipation the dissipative tail keeps the contact between the "
        "SSW and the crossed pulse loaded, so it rarely detaches before the free end and "
        "its speed is mostly not measured."
    )


def _speed_sentence(summary: Mapping) -> str:
    """' The elastic SSW's speed over Eq. 5 in the long chains (N = 120 and 121), fitted
    from where it detaches, is 1.020 (even) and 1.031 (odd).' for each conservative
    model whose longest even and odd chains both have a speed; '' otherwise."""
    speed = {
        (r["model"], r["N"]): r.get("speed_ratio")
        for r in summary.get("ssw_separation") or []
        if r.get("wave") == "LSTW"
    }
    out = ""
    for row in summary.get("ssw_far_field") or []:
        model = row["model"]
        if model not in (summary.get("conservative_models") or []):
            continue
        even, odd = speed.get((model, row["even_N"])), speed.get((model, row["odd_N"]))
        if even is None or odd is None:
            continue
        out += (
            f" The {model} SSW's speed over Eq. 5 in the long chains (N = {row['even_N']} "
            f"and {row['odd_N']}), fitted from where it detaches, is {even:.3f} (even) and "
            f"{odd:.3f} (odd)."
        )
    return out


def _attenuation_notes(summary: Mapping) -> list[str]:
    rows = summary.get("attenuation") or []
    if not rows:
        return []
    parts = [
        f"{r['model']}, N = {r['N']}: {1 - r['ratio_low']:.1%} at "
        f"{number(r['F_S1_low_N'], 3, 'unicode')} N, {1 - r['ratio_high']:.1%} at "
        f"{number(r['F_S1_high_N'], 3, 'unicode')} N"
        for r in rows
    ]
    return [
        "* Amplitude lost by a lone (reference) wave between S1 and S2: "
        + "; ".join(parts)
        + ". With Kuwabara-Kono dissipation the loss per contact grows like η/τ ∝ F_m^(1/6), "
        "so the waves cross with less than the F_m measured at S1, by a fraction that grows "
        "with F_m: C rises and the fitted exponent is flatter than −1/6. The ballistic "
        "argument of Eq. 6 assumes the amplitude at the crossing is the measured one."
    ]
