"""``summary.md``'s rows of the secondary solitary wave (SSW): the slopes at the
sensors, whether it is resolved there, where it separates along the chain and its
speed, and the even / odd ratios. Wording only: every number is a key of
``summary.json`` (``ssw_fits``, ``ssw_resolved``, ``ssw_separation``,
``ssw_parity_ratio``, ``ssw_far_field``)."""

from __future__ import annotations

from collections.abc import Mapping

from chain.report.naming import named
from chain.report.printed import plus_minus

#: A row of the table: quantity, paper, this run, note.
Row = tuple[str, str, str, str]


def ssw_rows(summary: Mapping) -> list[Row]:
    """Every SSW row of ``summary.md`` for the run's ``summary.json``, in the table's order."""
    return (
        _slope_rows(summary)
        + _resolved_rows(summary)
        + _separation_rows(summary)
        + _parity_rows(summary)
    )


def _pm(value, error, digits=2) -> str:
    """``value ± error`` by the one rule of :func:`chain.report.printed.plus_minus`
    (``digits`` decimals when there is no error), or ``n/a``."""
    return plus_minus(value, error, digits, style="unicode")


def _slope_rows(summary) -> list[Row]:
    """The SSW slope of every fit; an even chain's against the odd chain below it."""
    slopes = {
        (r["source"], r["model"], r["N"]): r
        for r in summary["ssw_fits"]
        if r.get("slope") is not None
    }
    rows = []
    for row in sorted(summary["ssw_fits"], key=lambda r: (r["source"], r["model"], str(r["N"]))):
        note = "SSW amplitude = slope × F_m"
        if isinstance(row["N"], int) and row["N"] % 2 == 0:
            odd = slopes.get((row["source"], row["model"], row["N"] - 1))
            if odd and row.get("slope") is not None and odd["slope"]:
                ratio = row["slope"] / odd["slope"]
                note += f"; {ratio:.2f} × the N = {row['N'] - 1} slope (even / odd)"
        paper_text = "∝ F_m, larger for even N (no value printed)"
        if row["source"] == "simulation":
            paper_text += "; simulated SSW much smaller than measured"
        value = _pm(row.get("slope"), row.get("slope_stderr"), 4)
        if row.get("slope_stat") is not None and row.get("slope") is not None:
            value = (
                f"{_pm(row['slope'], row['slope_stat'], 4)} stat ± "
                f"{row.get('slope_sys', float('nan')):.4f} sys"
            )
            note += (
                f"; {row.get('n_points', 0)} points, {row.get('n_resolved', 0)} resolved "
                "(the rest measured or upper limits)"
            )
        if row.get("slope") is None:
            value = f"n/a ({row.get('n_points', 0)} points)"
            note = "no measurable SSW at the sensors: nothing to fit"
        rows.append(
            (
                f"SSW slope, {named(summary, row['source'], row['model'], row['N'])}",
                paper_text,
                value,
                note,
            )
        )
    return rows


def _resolved_rows(summary) -> list[Row]:
    """Whether the SSW is resolved at each sensor: yes/no with the count of shots."""
    rows = []
    for row in summary.get("ssw_resolved", []):
        counts = f"{row['n_resolved']} of {row['n_total']} shots"
        rows.append(
            (
                f"SSW resolved at {row['sensor']}, "
                f"{named(summary, row['source'], row['model'], row['N'])}",
                _paper_ssw_shown(row),
                f"{'yes' if row['resolved'] else 'no'} ({counts})",
                "a distinct bump behind the crossed pulse's trailing minimum, above "
                "2 × (template misfit + 3 σ noise); yes if in at least half the shots",
            )
        )
    return rows


def _paper_ssw_shown(row: Mapping) -> str:
    """What the paper shows of the SSW at the sensors of this chain (Fig. 2 and 3:
    panels C and D are the 26-bead chain)."""
    if row["N"] == 26:
        return "yes (Fig. 2 and 3, C and D)"
    if row["N"] == 25 and row["source"] == "experiment":
        return "yes (Sec. IV, odd and even N; not shown)"
    return "—"


def _separation_rows(summary) -> list[Row]:
    """Where the tracked SSW separates from the crossed pulse, and its speed / Eq. 5
    (LSTW; RSTW is its mirror image in the simulation)."""
    rows = []
    for row in summary.get("ssw_separation", []):
        if row["wave"] != "LSTW":
            continue
        who = f"simulation, {row['model']}, N = {row['N']}"
        shots = f"{row.get('n_shots_separated', 0)} of {row.get('n_shots', 0)} shots separate"
        contact = row["first_separated_contact"]
        where = "never within the chain"
        if contact is not None:
            where = f"contact {contact} ({row['distance_beads']:g} beads from the collision point)"
        rows.append((f"SSW first separated contact (LSTW), {who}", "—", where, shots))
        ratio = row.get("speed_ratio")
        rows.append(
            (
                f"SSW speed / Eq. 5 for its amplitude, {who}",
                "—",
                "n/a" if ratio is None else f"{ratio:.3f}",
                "fitted where detached from the crossed pulse, before the free end"
                if ratio is not None
                else "never separated"
                if contact is None
                else "not detached over 3 contacts before the free end unloads the chain",
            )
        )
    return rows


def _parity_rows(summary) -> list[Row]:
    """The SSW slope of N = 26 over N = 25 (the paper's even/odd claim)."""
    rows = []
    for row in summary.get("ssw_parity_ratio", []):
        who = named(summary, row["source"], row["model"]) + ", N = 26 : N = 25"
        ratio = row.get("ratio")
        rows.append(
            (
                f"SSW slope ratio, {who}",
                "> 1 (larger for even N, Sec. V)",
                "n/a" if ratio is None else _pm(ratio, row.get("ratio_err"), 2),
                "no SSW slope of one chain or both"
                if ratio is None
                else "at the sensors; the error is mostly the template misfit (systematic)",
            )
        )
    for row in summary.get("ssw_far_field", []):
        rows.append(
            (
                f"SSW far field, even : odd, simulation, {row['model']}, "
                f"N = {row['even_N']} : {row['odd_N']}",
                "> 1 (larger for even N, Sec. V)",
                _pm(row["ratio"], row["ratio_err"], 3),
                f"SSW / F_m = {_pm(100 * row['even'], 100 * row['even_err'], 3)} % : "
                f"{_pm(100 * row['odd'], 100 * row['odd_err'], 3)} % (long chains, at the "
                "farthest contact before the free end; error: shot spread and change over "
                "the last 3 contacts)",
            )
        )
    return rows
