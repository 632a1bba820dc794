"""`ies sweep`: a stepped-sine frequency response like Fig. 5 of the seed paper (Sects. 5.1, 5.2).

The helpers `add_system_arguments`, `add_protocol_arguments`, `build_system` and `build_protocol` are shared
with `ies overview`.
"""
from __future__ import annotations

import argparse
from contextlib import contextmanager
from pathlib import Path
from typing import Iterator

NAME = "sweep"
HELP = "stepped-sine frequency response (mean and max amplitude per eta, spread over repetitions; Fig. 5)"

SEQUENCE_CHOICES = ("up", "down", "up-down-up", "up-down-up-down-up")


def add_system_arguments(parser: argparse.ArgumentParser) -> None:
    """Model and impactor options (Table 2 parameters)."""
    parser.add_argument("--model", metavar="FILE", help="modal-model file (default: the built-in model of the seed rig)")
    parser.add_argument("--D", type=float, metavar="D1", help="modal damping ratio of mode 1 (-), default the model's (0.00085)")
    parser.add_argument("--g", type=float, metavar="M", help="clearance g in m (default 0.58e-3 m)")
    parser.add_argument("--k-H", dest="k_H", type=float, metavar="N/M^1.5",
                        help="Hertz constant k_H in N/m^1.5 (default 282e3 N/mm^1.5 = 8.918e9 N/m^1.5)")
    parser.add_argument("--no-impactor", action="store_true", help="simulate the host structure alone (linear)")


def add_protocol_arguments(parser: argparse.ArgumentParser, *, default_reps: int) -> None:
    """Stepped-sine options (Sect. 5.1)."""
    parser.add_argument("--eta", default="0.96:1.02:31", metavar="START:STOP:N",
                        help="grid of eta = Omega/omega_1 (default 0.96:1.02:31)")
    parser.add_argument("--sequence", default="up", choices=SEQUENCE_CHOICES, help="sweep legs per run (default up)")
    parser.add_argument("--repetition", default="leg", choices=("leg", "run"),
                        help="what counts as one repetition: each leg (the experiment's counting, default) or each run from rest")
    parser.add_argument("--start", default="base-velocity", choices=("base-velocity", "rest"),
                        help="initial conditions of each run: homogeneous relative ICs under the sine excitation, "
                             "the sphere starting with the base's peak velocity so it rattles from the first point "
                             "(default; reproduces Figs. 5-6), or at rest (the sphere stays idle until the response "
                             "exceeds the clearance: an up-sweep then stays linear far into the resonance)")
    parser.add_argument("--wait", type=float, default=None, metavar="S",
                        help="wait time per frequency in s (default 3, or 15 with --no-impactor, Sect. 5.1)")
    parser.add_argument("--hold", type=float, default=5.0, metavar="S", help="hold time per frequency in s (default 5)")
    parser.add_argument("--reps", type=int, default=default_reps, metavar="N",
                        help=f"runs from rest, each with its own random frequency offsets (default {default_reps})")
    parser.add_argument("--seed", type=int, default=0, metavar="N", help="random seed (default 0)")
    parser.add_argument("--perturbation", type=float, default=5e-4, metavar="REL",
                        help="half-width of the uniform relative frequency offset per point (default 5e-4)")
    parser.add_argument("--integrator", default="exact", metavar="NAME",
                        help="time integrator: exact (default; closed-form free flight, located contacts) or ode3 (the paper's fixed step)")
    parser.add_argument("--dt-scale", dest="dt_scale", type=float, default=1.0, metavar="X",
                        help="ode3 step as a multiple of the paper's 2 pi/(15 omega_9) (default 1)")


def parse_grid(text: str, option: str):
    """'START:STOP:N' -> (start, stop, n); one value 'X' -> (X, X, 1). One-line error otherwise."""
    from sim.errors import SimulationInputError

    parts = text.split(":")
    try:
        if len(parts) == 1:
            value = float(parts[0])
            return value, value, 1
        if len(parts) == 3:
            return float(parts[0]), float(parts[1]), int(parts[2])
    except ValueError:
        pass
    raise SimulationInputError(f"{option} must look like START:STOP:N (e.g. 0.96:1.02:31), got {text!r}")


def build_system(args: argparse.Namespace):
    """(model, impactor or None) from the options; every bad value ends in one SimulationInputError line."""
    from sim.errors import SimulationInputError
    from sim.system import CLEARANCE_NOMINAL, K_H_NOMINAL, SPHERE_MASS, Impactor

    if args.model:
        try:
            from sim.modal_file import load_modal_model
        except ImportError as exc:
            raise SimulationInputError("modal-model files are not supported in this installation (sim.modal_file missing)") from exc
        model = load_modal_model(args.model)
    else:
        try:
            from sim.rig import seed_rig_model
        except ImportError as exc:
            raise SimulationInputError("the built-in rig model is not available in this installation; pass --model FILE") from exc
        model = seed_rig_model(n_modes=9)
    if args.D is not None:
        model = model.with_damping(args.D)
    clearance = CLEARANCE_NOMINAL if args.g is None else args.g
    k_H = K_H_NOMINAL if args.k_H is None else args.k_H
    impactor = Impactor(SPHERE_MASS, clearance, k_H)  # validates g and k_H even with --no-impactor
    return model, (None if args.no_impactor else impactor)


def build_protocol(args: argparse.Namespace):
    """The SteppedSine of the options."""
    from sim.protocol import SteppedSine

    start, stop, n = parse_grid(args.eta, "--eta")
    wait = args.wait if args.wait is not None else (15.0 if args.no_impactor else 3.0)
    return SteppedSine(eta_start=start, eta_stop=stop, n_eta=n, sequence=args.sequence, wait=wait,
                       hold=args.hold, perturbation=args.perturbation, repetition=args.repetition,
                       integrator=args.integrator, dt_scale=args.dt_scale, start=args.start)


@contextmanager
def output_folder(path: str | None) -> Iterator[Path | None]:
    """--out DIR, created up front (a clear error if it cannot be a folder) and removed again if the command
    fails before writing anything into it (no empty result folders after a bad input)."""
    from uq.errors import StudyError

    if path is None:
        yield None
        return
    folder = Path(path)
    if folder.exists() and not folder.is_dir():
        raise StudyError(f"--out {folder} exists and is not a folder; choose another path")
    created = not folder.exists()
    folder.mkdir(parents=True, exist_ok=True)
    try:
        yield folder
    except BaseException:
        if created and not any(folder.iterdir()):
            folder.rmdir()
        raise


def write_csv(path: Path, header: list[str], columns: list) -> None:
    """Columns as CSV, written atomically."""
    from uq.output import write_text

    rows = [",".join(header)]
    for values in zip(*columns):
        rows.append(",".join(v if isinstance(v, str) else repr(float(v)) for v in values))
    write_text(path, "\n".join(rows) + "\n")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--level", type=float, required=True, metavar="L",
                        help="excitation level a_base/a_base* (-), a_base* = 2 D* g*/(phi_c phi^T M b)")
    add_protocol_arguments(parser, default_reps=5)
    add_system_arguments(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--plot", metavar="FILE", help="write a Fig. 5-like plot (PNG/PDF by suffix)")
    parser.add_argument("--out", metavar="DIR", help="write sweep.csv (data) and sweep.json (data + metadata)")


def plot_sweep(result, path: str, title: str) -> None:
    """Fig. 5: mean (solid) and max (dashed) amplitude vs eta with the repetition spread as bands."""
    from uq.output import plot_to

    with plot_to(path, figsize=(6.0, 4.0)) as (fig, ax):
        ax.fill_between(result.eta, result.max_lo, result.max_hi, color="tab:red", alpha=0.2, lw=0)
        ax.plot(result.eta, result.max, "--", color="tab:red", label="max")
        ax.fill_between(result.eta, result.mean_lo, result.mean_hi, color="tab:blue", alpha=0.25, lw=0)
        ax.plot(result.eta, result.mean, "-", color="tab:blue", label="mean")
        ax.set_xlabel(r"$\eta = \Omega/\omega^*$")
        ax.set_ylabel(r"$a / a^{noabs*}$")
        ax.set_title(title)
        ax.set_ylim(bottom=0)
        ax.legend()
        ax.grid(alpha=0.3)


def run(args: argparse.Namespace) -> int:
    import time

    from sim.protocol import check_level, sweep
    from uq.output import dumps, write_text

    started = time.perf_counter()
    level = check_level(args.level)
    protocol = build_protocol(args)
    model, impactor = build_system(args)
    with output_folder(args.out) as folder:
        result = sweep(model, impactor, level, protocol, reps=args.reps, seed=args.seed)
        data = result.to_dict()
        data.update(wall_time_s=time.perf_counter() - started, seed=args.seed, reps=args.reps, model=model.source,
                    impactor=None if impactor is None else {"mass_kg": impactor.mass, "g_m": impactor.clearance,
                                                            "k_H_N_per_m1p5": impactor.k_H},
                    D1=float(model.damping_ratios[0]))
        if folder is not None:
            write_csv(folder / "sweep.csv",
                      ["eta", "mean", "mean_lo", "mean_hi", "max", "max_lo", "max_hi", "cv", "impacts_per_period",
                       "regime"],
                      [result.eta, result.mean, result.mean_lo, result.mean_hi, result.max, result.max_lo,
                       result.max_hi, result.cv, result.impacts_per_period, result.regime_per_eta])
            write_text(folder / "sweep.json", dumps(data) + "\n")
    if args.plot:
        plot_sweep(result, args.plot, f"a_base/a_base* = {level:g}, {result.n_samples} samples ({protocol.integrator})")
    if args.json:
        print(dumps(data))
    else:
        print(f"# a_base/a_base* = {level:g}: {result.n_runs} runs, {result.n_samples} samples, {protocol.integrator}, "
              f"{data['wall_time_s']:.1f} s")
        print(f"{'eta':>7} {'mean':>8} {'max':>8} {'cv':>6} {'imp/T':>6}  regime")
        for i, eta in enumerate(result.eta):
            print(f"{eta:7.4f} {result.mean[i]:8.4f} {result.max[i]:8.4f} {result.cv[i]:6.3f} "
                  f"{result.impacts_per_period[i]:6.2f}  {result.regime_per_eta[i]}")
        print(f"resonant mean {result.resonant_mean:.4f} at eta {result.eta_resonant_mean:.4f} ({result.regime}); "
              f"resonant max {result.resonant_max:.4f} at eta {result.eta_resonant_max:.4f}")
    return 0
