"""The ``hertzchain`` command: simulate a chain, analyse a trace file, print closed forms.

Run ``hertzchain --help`` or ``hertzchain <command> --help``.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
from collections.abc import Mapping, Sequence

from chain.apparatus.shots import trace_table
from chain.errors import ParameterError, check_bead_numbers, require_positive
from chain.physics.builders import uniform_chain
from chain.physics.integrator import IntegrationError
from chain.physics.materials import MATERIALS, get_material
from chain.physics.model import PAPER_BEAD_RADIUS, PCB_200B02_STIFFNESS
from chain.physics.simulation import DEFAULT_RECORD_INTERVAL, felt_contacts, simulate
from chain.traces import TraceFormatError, write_traces

_DESCRIPTION = """\
Solitary-wave collisions in a Hertzian chain of beads (Santibanez et al.).

commands:
  simulate   integrate Eq. 1 (optionally with Kuwabara-Kono dissipation, sensor beads,
             strikers) for one launch and write a trace file (CSV, the project's trace
             format: one row per sample, a force_bead<n>_N column per recorded bead)
  analyse    fit the pulses of a trace file (cos^6 fits) and print them as CSV
  theory     print the closed forms for a material: kappa, bead mass, C_bal (Eq. 6),
             C_bal with the exact Hertz contact time, wave speed (Eq. 5)
  check      check a pipeline run: every contract file present, headline numbers
             (C, exponents, SSW slopes, C_bal, energy drift) within tolerance of a
             committed reference; warns when its packages differ from the lock
  store      the result store's folder, number of entries and size; `store prune`
             removes the entries no run folder under results/ shows (--older-than:
             and those stored before a date; --dry-run: only say what would go)

Beads are numbered 1..N as in the paper. Units: SI (m, s, m/s, N).
Example:
  hertzchain simulate -N 26 --speed 0.3 --kind collision --sensors 10 17 -o traces.csv
"""


#: Per command, the library's parameter names (as its checks name them) and the option
#: that sets each: the library checks a value once, in one place, and the message
#: names the option the user typed.
_OPTIONS = {
    "simulate": {
        "n_beads": "-N",
        "radius": "--radius",
        "eta": "--eta",
        "striker_radius": "--striker-radius",
        "sensor_beads": "--sensors",
        "v_left": "--speed",
        "v_right": "--speed",  # --speed for both ends (0 for --kind reference)
        "duration": "--duration",
        "dt": "--dt",
        "record_interval": "--record-interval",
    },
    # The closed forms check the bead radius wherever they first use it.
    "theory": {"radius": "--radius", "radius_a": "--radius", "radius_b": "--radius"},
    "analyse": {"estimators": "--estimator"},
}


def in_option_words(message: str, options: Mapping[str, str]) -> str:
    """``message`` with each library parameter name of ``options`` (whole words, with an
    index such as ``eta[contact 1]``) replaced by its command-line option, and the
    repetition this can make ("--speed or --speed") said once.

    Parameters
    ----------
    message : str
        A library error message (it names the parameter).
    options : mapping
        Library parameter name -> option, e.g. ``{"v_left": "--speed"}``.
    """
    if not options:
        return message
    names = "|".join(re.escape(name) for name in sorted(options, key=len, reverse=True))
    # A name, not part of a word, option or file name (dt.csv stays dt.csv).
    named = re.sub(rf"(?<![\w./-])({names})(\[[^\]]*\])?(?![\w./-])",
                   lambda match: options[match.group(1)], message)  # fmt: skip
    return re.sub(r"(--?[\w-]+) or \1(?![\w-])", r"\1", named)


def _build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="hertzchain",
        description=_DESCRIPTION,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    commands = parser.add_subparsers(dest="command", required=True, metavar="command")
    for add_command in (
        _add_simulate,
        _add_analyse,
        _add_theory,
        _add_check,
        _add_check_config,
        _add_store,
    ):
        add_command(commands)
    return parser


def _add_simulate(commands) -> None:
    sim = commands.add_parser(
        "simulate",
        help="simulate one launch and write a trace file",
        description="Simulate one launch of a chain of equal beads and write a trace CSV.",
    )
    sim.add_argument("-N", "--n-beads", type=int, required=True, help="number of beads N >= 2")
    sim.add_argument(
        "--speed", type=float, required=True, help="launch speed V0 of bead 1 (and N), m/s"
    )
    sim.add_argument(
        "--kind",
        choices=("collision", "reference"),
        default="collision",
        help="collision: +V0 on bead 1 and -V0 on bead N; reference: +V0 on bead 1 alone "
        "(default: collision)",
    )
    sim.add_argument(
        "--duration", type=float, default=2.6e-3, help="simulated time, s (default 2.6e-3)"
    )
    sim.add_argument("--dt", type=float, default=None, help="RK4 time step, s (default: automatic)")
    sim.add_argument(
        "--record-interval",
        type=float,
        default=DEFAULT_RECORD_INTERVAL,
        help=f"time between recorded samples, s (default {DEFAULT_RECORD_INTERVAL:g})",
    )
    sim.add_argument(
        "--sensors",
        type=int,
        nargs="+",
        default=None,
        help="beads to record, S1 first (default: every bead 1..N)",
    )
    _add_chain_options(sim)
    sim.add_argument("--model-name", default="cli", help="value of the trace 'model' column")
    sim.add_argument("-o", "--output", required=True, help="output trace CSV path")


def _add_chain_options(sim) -> None:
    """The options of ``simulate`` that describe the chain (beads, sensors, strikers)."""
    sim.add_argument(
        "--material",
        choices=sorted(MATERIALS),
        default="steel_100C6",
        help="bead material (default steel_100C6, the paper's)",
    )
    sim.add_argument(
        "--radius",
        type=float,
        default=PAPER_BEAD_RADIUS,
        help=f"bead radius, m (default {PAPER_BEAD_RADIUS:g})",
    )
    sim.add_argument(
        "--eta",
        type=float,
        default=0.0,
        help="Kuwabara-Kono relaxation time, s (paper: 0.58e-6; default 0: Eq. 1)",
    )
    sim.add_argument(
        "--sensor-beads",
        action="store_true",
        help="model the --sensors beads as split sensor beads (PCB 200B02, "
        f"k_s = {PCB_200B02_STIFFNESS:g} N/m) and record their readings",
    )
    sim.add_argument(
        "--striker-radius",
        type=float,
        default=None,
        help="launch with spherical strikers of this radius, m (paper: 4e-3) "
        "instead of giving V0 to the end beads",
    )


def _add_analyse(commands) -> None:
    analyse = commands.add_parser(
        "analyse",
        help="fit the pulses of a trace file",
        description="Segment and fit every pulse of a trace CSV; print one row per pulse.",
    )
    analyse.add_argument("traces", help="trace CSV (hertzchain simulate output)")
    analyse.add_argument(
        "--estimator",
        default="fit_full",
        help="fit_full (paper: cos^6 fit on |t-T| < tau), peak or fit_rise",
    )
    analyse.add_argument("-o", "--output", default=None, help="write the table here (CSV)")


def _add_theory(commands) -> None:
    theory = commands.add_parser(
        "theory",
        help="print closed forms for a material",
        description="Print kappa, bead mass, C_bal (Eq. 6 as printed and with the exact "
        "Hertz contact time) and the Eq. 5 wave speed at a given force, as JSON.",
    )
    theory.add_argument("--material", choices=sorted(MATERIALS), default="steel_100C6")
    theory.add_argument("--radius", type=float, default=PAPER_BEAD_RADIUS, help="bead radius, m")
    theory.add_argument(
        "--force", type=float, default=100.0, help="peak force F_m for the wave speed, N"
    )


def _add_check(commands) -> None:
    check = commands.add_parser(
        "check",
        help="check a run against the results contract and a reference",
        description="Check results/<run_name>: contract files and columns, its SHA256SUMS "
        "(written only by a run that succeeded), and the headline "
        "numbers of summary.json against a reference file within its tolerances. "
        "Exit status 1 lists every failure. Packages the run had at other versions than "
        "the lock (requirements/py3XX.lock) are named in a warning.",
    )
    check.add_argument("run_folder", help="results/<run_name>")
    check.add_argument(
        "--reference", required=True, help="reference JSON (tests/reference/paper_headline.json)"
    )
    check.add_argument(
        "--no-experiment", action="store_true", help="the run has no experiment side (no Fig. 2)"
    )
    check.add_argument(
        "--write-reference",
        metavar="WHY",
        default=None,
        help="instead of checking, (re)write the reference from this run, recording WHY; "
        "commit it only in a reviewed commit that says why",
    )


def _add_check_config(commands) -> None:
    check = commands.add_parser(
        "check-config",
        help="name the file and line of a YAML mistake in config files",
        description="Parse config files (config.yaml, what-if overlays) as the pipeline "
        "does and name the file, line and column of a YAML mistake or a repeated key. "
        "Snakemake reads --configfile overlays before the workflow's own checks run, and "
        "its message for an overlay that is not YAML names neither file nor line. "
        "Exit status 1 if any file has a problem.",
    )
    check.add_argument("configfiles", nargs="+", help="YAML config files")


def _add_store(commands) -> None:
    store = commands.add_parser(
        "store",
        help="what the result store holds, and pruning it",
        description="Print the result store's folder (HERTZCHAIN_STORE, default "
        "results/.store), its number of entries and their size. Creates nothing.",
    )
    actions = store.add_subparsers(dest="action", metavar="action")
    prune = actions.add_parser(
        "prune",
        help="remove the entries no run folder shows",
        description="Remove the entries that no run folder under results/ holds (its "
        "SHA256SUMS lists every file of the entry at its path with the stored SHA-256), "
        "and with --older-than those stored before that day, held or not.",
    )
    prune.add_argument(
        "--older-than",
        type=_day,
        metavar="YYYY-MM-DD",
        help="also remove the entries stored before this day, whether held or not",
    )
    prune.add_argument(
        "--dry-run", action="store_true", help="say what would go and the bytes it frees"
    )
    prune.add_argument(
        "--results", default="results", help="the folder of the run folders (default results)"
    )


def _day(text: str):
    import datetime

    try:
        return datetime.date.fromisoformat(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a day (YYYY-MM-DD)") from None


def _store(args: argparse.Namespace) -> int:
    import os

    from chain.pipeline.run import store_admin
    from chain.pipeline.run.store_path import StoreError, open_store

    try:
        store = open_store(os.environ, create=False)
    except StoreError as error:
        print(f"hertzchain store: error: {error}", file=sys.stderr)
        return 2
    if not os.path.isdir(store):
        print(f"no result store at {store}")
        return 0
    if args.action == "prune":
        lines = store_admin.prune(store, args.results, args.older_than, args.dry_run)
    else:
        lines = [store_admin.describe(store)]
    print("\n".join(lines))
    return 0


def _check_config(args: argparse.Namespace) -> int:
    from chain.pipeline.config.files import main as check_config_files

    return check_config_files(args.configfiles)


def _check(args: argparse.Namespace) -> int:
    from pathlib import Path

    from chain.pipeline.provenance import headline
    from chain.pipeline.provenance.checksums import checksum_problems
    from chain.pipeline.provenance.record import lock_warnings

    folder = Path(args.run_folder)
    summary_path = folder / "summary.json"
    if not summary_path.is_file():
        raise FileNotFoundError(f"{summary_path}: no summary; run the pipeline first")
    summary = json.loads(summary_path.read_text())
    if args.write_reference is not None:
        reference = headline.reference_from_summary(summary, args.write_reference)
        Path(args.reference).parent.mkdir(parents=True, exist_ok=True)
        Path(args.reference).write_text(json.dumps(reference, indent=2, sort_keys=True) + "\n")
        print(f"wrote {args.reference} ({len(reference['values'])} numbers)")
        return 0
    reference = json.loads(Path(args.reference).read_text())
    failures = headline.missing_contract_files(folder, experiment=not args.no_experiment)
    failures += checksum_problems(folder)
    failures += headline.compare_with_reference(headline.headline_numbers(summary), reference)
    for failure in failures:
        print(f"FAIL {failure}")
    # Versions other than the lock's may move a number; they warn, never fail.
    for warning in lock_warnings(summary.get("provenance")):
        print(f"WARNING {warning}")
    checked = len(reference["values"])
    if failures:
        print(f"{len(failures)} problem(s); {checked} headline numbers in the reference")
        return 1
    print(f"ok: contract files present, {checked} headline numbers within tolerance")
    return 0


def _simulate(args: argparse.Namespace) -> int:
    material = get_material(args.material)
    beads = args.sensors if args.sensors is not None else list(range(1, args.n_beads + 1))
    model = uniform_chain(
        args.n_beads,
        material,
        args.radius,
        args.eta,
        sensor_beads=beads if args.sensor_beads else (),
        striker_radius=args.striker_radius,
    )
    # The trace format's rule for sensor columns (S1 first), before any integration.
    beads = check_bead_numbers("--sensors", beads, args.n_beads)
    v_right = args.speed if args.kind == "collision" else 0.0
    try:
        result = simulate(
            model,
            args.speed,
            v_right,
            duration=args.duration,
            dt=args.dt,
            record_interval=args.record_interval,
            # Only what the table reads (sensor springs are always kept).
            contacts=() if args.sensor_beads else felt_contacts(model, beads),
            beads=(),
        )
    except MemoryError:
        raise ParameterError(
            f"the record of --duration {args.duration:g} s every --record-interval "
            f"{args.record_interval:g} s does not fit in memory"
        ) from None
    table = trace_table(
        result,
        beads,
        kind=args.kind,
        model_name=args.model_name,
        readout="sensor" if args.sensor_beads else "felt",
    )
    try:
        write_traces(table, args.output)
    except TraceFormatError as error:  # the sensors are valid: the samples are not
        raise ParameterError(
            f"--duration {args.duration:g} s and --record-interval {args.record_interval:g} s "
            f"give a trace the format refuses: {error}"
        ) from None
    print(
        f"wrote {args.output}: N={args.n_beads}, {len(result.time)} samples, "
        f"dt={result.dt:.3e} s, energy drift {result.energy_drift.max():.2e}",
        file=sys.stderr,
    )
    return 0


def _analyse(args: argparse.Namespace) -> int:
    from chain.analysis.pulse_rows import pulse_table  # analysis is imported only when asked for
    from chain.traces import read_traces

    table = pulse_table(read_traces(args.traces), estimators=(args.estimator,))
    if args.output:
        from chain.atomic import write_csv_atomic

        write_csv_atomic(table, args.output)
    else:
        table.to_csv(sys.stdout, index=False, float_format="%.6g")
    return 0


def _theory(args: argparse.Namespace) -> int:
    from chain.physics import theory

    material = get_material(args.material)
    radius = args.radius
    # The closed forms take arrays of forces and leave them unchecked.
    require_positive("--force", args.force)
    values = {
        "material": material.name,
        "radius_m": radius,
        # kappa, bead mass, C_bal as printed and exact: the run constants of summary.json
        **theory.ballistic_constants(material.name, radius),
        "F_m_N": args.force,
        "wave_speed_m_s": theory.nesterenko_speed_from_force(args.force, material, radius),
        "bead_velocity_m_s": theory.bead_velocity_from_force(args.force, material, radius),
        "tau_s": theory.pulse_half_width(args.force, material, radius),
    }
    print(json.dumps(values, indent=2))
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``hertzchain`` console script; returns the exit status."""
    args = _build_parser().parse_args(argv)
    handlers = {
        "simulate": _simulate,
        "analyse": _analyse,
        "theory": _theory,
        "check": _check,
        "check-config": _check_config,
        "store": _store,
    }
    try:
        return handlers[args.command](args)
    except (ParameterError, TraceFormatError, IntegrationError, FileNotFoundError) as error:
        message = in_option_words(str(error), _OPTIONS.get(args.command, {}))
        print(f"hertzchain {args.command}: error: {message}", file=sys.stderr)
        return 2


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
