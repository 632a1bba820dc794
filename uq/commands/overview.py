"""`ies overview`: resonant response level vs excitation level, like Fig. 6 of the seed paper (Sect. 5.3)."""
from __future__ import annotations

import argparse

from uq.commands.sweep import add_protocol_arguments, add_system_arguments

NAME = "overview"
HELP = "resonant response level (largest mean and max over eta) vs excitation level a_base/a_base* (Fig. 6)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--levels", required=True, metavar="L1,L2,..|START:STOP:N",
                        help="excitation levels a_base/a_base* (-), a list like 1.26,5.3,6.7,7.4 or a grid 2:8:13")
    add_protocol_arguments(parser, default_reps=3)
    add_system_arguments(parser)
    parser.add_argument("--json", action="store_true", help="print one JSON object")
    parser.add_argument("--plot", metavar="FILE", help="write a Fig. 6-like plot (PNG/PDF by suffix)")
    parser.add_argument("--out", metavar="DIR", help="write overview.csv (data) and overview.json (data + metadata)")


def parse_levels(text: str) -> list[float]:
    """'1.26,5.3' or 'START:STOP:N' -> levels; each must be positive."""
    import numpy as np

    from sim.errors import SimulationInputError
    from sim.protocol import check_level
    from uq.commands.sweep import parse_grid

    if ":" in text:
        start, stop, n = parse_grid(text, "--levels")
        if n < 1 or (n > 1 and stop <= start):
            raise SimulationInputError(f"--levels {text!r} is empty or reversed; give START < STOP and N >= 1")
        values = list(np.linspace(start, stop, n))
    else:
        try:
            values = [float(v) for v in text.split(",") if v.strip()]
        except ValueError:
            raise SimulationInputError(
                f"--levels must be numbers like 1.26,5.3,6.7 or a grid START:STOP:N, got {text!r}") from None
    if not values:
        raise SimulationInputError("--levels is empty; give at least one excitation level")
    return [check_level(v) for v in values]


def plot_overview(levels, results, path: str, title: str) -> None:
    """Fig. 6: resonant mean (solid) and max (dashed) level vs excitation level, regime labels on top."""
    from uq.output import plot_to

    with plot_to(path, figsize=(6.5, 4.0)) as (fig, ax):
        ax.plot(levels, [r.resonant_max for r in results], "s--", color="tab:red", label="max")
        ax.plot(levels, [r.resonant_mean for r in results], "o-", color="tab:blue", label="mean")
        for level, r in zip(levels, results):
            ax.annotate(r.regime, (level, 1.0), xycoords=("data", "axes fraction"), ha="center", va="bottom",
                        fontsize=7, rotation=90)
        ax.set_xlabel(r"$a_{base} / a^*_{base}$")
        ax.set_ylabel(r"resonant level $a / a^{noabs*}$")
        ax.set_ylim(bottom=0)
        ax.set_title(title, pad=28)
        ax.legend()
        ax.grid(alpha=0.3)


def run(args: argparse.Namespace) -> int:
    import time

    from tqdm import tqdm

    from sim.protocol import sweep
    from uq.commands.sweep import build_protocol, build_system, output_folder, write_csv
    from uq.output import dumps, write_text

    started = time.perf_counter()
    levels = parse_levels(args.levels)
    protocol = build_protocol(args)
    model, impactor = build_system(args)
    with output_folder(args.out) as folder:
        results = []
        for level in tqdm(levels, desc="overview", unit="level", disable=None, leave=False):
            results.append(sweep(model, impactor, level, protocol, reps=args.reps, seed=args.seed))
        data = {
            "levels": levels,
            "resonant_mean": [r.resonant_mean for r in results],
            "resonant_max": [r.resonant_max for r in results],
            "resonant_mean_lo": [float(r.resonant_mean_samples.min()) for r in results],
            "resonant_mean_hi": [float(r.resonant_mean_samples.max()) for r in results],
            "resonant_max_lo": [float(r.resonant_max_samples.min()) for r in results],
            "resonant_max_hi": [float(r.resonant_max_samples.max()) for r in results],
            "eta_resonant_mean": [r.eta_resonant_mean for r in results],
            "eta_resonant_max": [r.eta_resonant_max for r in results],
            "regime": [r.regime for r in results],
            "impacts_per_period": [float(r.impacts_per_period[r.eta == r.eta_resonant_mean][0]) for r in results],
            "sweeps": [r.to_dict() for r in results],
            "reps": args.reps, "seed": args.seed, "model": model.source,
            "wall_time_s": time.perf_counter() - started,
        }
        if folder is not None:
            write_csv(folder / "overview.csv",
                      ["level", "resonant_mean", "resonant_mean_lo", "resonant_mean_hi", "resonant_max",
                       "resonant_max_lo", "resonant_max_hi", "eta_resonant_mean", "eta_resonant_max",
                       "impacts_per_period", "regime"],
                      [data[k] for k in ("levels", "resonant_mean", "resonant_mean_lo", "resonant_mean_hi",
                                         "resonant_max", "resonant_max_lo", "resonant_max_hi", "eta_resonant_mean",
                                         "eta_resonant_max", "impacts_per_period", "regime")])
            write_text(folder / "overview.json", dumps(data) + "\n")
    if args.plot:
        plot_overview(levels, results, args.plot, f"{protocol.sequence}, {args.reps} runs ({protocol.integrator})")
    if args.json:
        print(dumps(data))
    else:
        print(f"{'level':>7} {'res.mean':>9} {'res.max':>9} {'eta(mean)':>9} {'imp/T':>6}  regime")
        for i, level in enumerate(levels):
            print(f"{level:7.3f} {data['resonant_mean'][i]:9.4f} {data['resonant_max'][i]:9.4f} "
                  f"{data['eta_resonant_mean'][i]:9.4f} {data['impacts_per_period'][i]:6.2f}  {data['regime'][i]}")
    return 0
