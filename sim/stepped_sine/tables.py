"""Tables of stepped-sine results: a frequency response (Fig. 5, Sect. 5.2) and the resonant level against the
excitation level (Fig. 6, Sect. 5.3), as `ies sweep`, `ies overview` and the uq response studies write and print
them. Amplitudes are a / a_noabs* and levels a_base / a_base* (dimensionless, Sect. 5); a column with a unit
says it in its name (a_base_m). Each file's columns and keys, with unit and meaning, are the `OutputFile`
tables below (`sim.common.outputs`), from which the output reference uq/OUTPUTS.md is generated.
"""
from __future__ import annotations

from typing import Any, Sequence

from sim.common.outputs import Column, OutputFile
from sim.stepped_sine.measures import PAPER_OPTIMUM_LEVEL, PAPER_REDUCTION_MAX, PAPER_REDUCTION_MEAN
from sim.stepped_sine.protocol import SweepResult, scattering_keys

#: the energy scattering and impact measures (Sect. 5.5, Appendix D; `sim.stepped_sine.measures`), appended to both
#: tables: the measure names, the input power with its unit (W) in the name
SCATTERING = (
    Column("significant_impacts_per_period", "-", "impacts with impulse >= 0.1 of the hold's reference impulse, per "
           "excitation period (`sim.stepped_sine.measures`)"),
    Column("restitution", "-", "modal coefficient of restitution r of Eq. D.1 from the tip's fundamental harmonic (median "
           "over the significant impacts of the last 50 periods; NaN without)"),
    Column("restitution_wall", "-", "the same from the fundamental harmonic of the wall that is hit"),
    Column("higher_mode_energy_share", "-", "share of the host's mechanical energy in modes 2..N at the release of the "
           "significant impacts, averaged"),
    Column("higher_mode_energy_share_mean", "-", "the same share of the time-averaged modal kinetic energies over the hold"),
    Column("dissipation_fundamental", "-", "energy dissipated by mode 1's modal damping, as a share of the input work"),
    Column("dissipation_higher_modes", "-", "energy dissipated by the modal damping of modes 2..N, share of the input"),
    Column("dissipation_contact", "-", "energy dissipated in the contacts (Eq. 10; 0 for the elastic law), share of the input"),
    Column("input_power_W", "W", "mean power of the base excitation over the hold (frame of Eq. 2)"),
    Column("balance_error", "-", "(input - dissipated - change of stored energy) / input over the hold (largest magnitude "
           "over the samples)"),
    Column("dissipation_friction", "-", "energy dissipated by dry friction at the floor (Appendix C), share of the input"),
)
SCATTERING_COLUMNS = tuple(c.name for c in SCATTERING)
#: the response's nature (`sim.stepped_sine.dynamics`), in sweep.csv after the regime only with `ies sweep --lyapunov`
NATURE = (
    Column("lyapunov_per_period", "-", "only with --lyapunov: the largest Lyapunov exponent over the hold, natural log "
           "per excitation period, averaged over the samples (`sim.stepped_sine.dynamics`)"),
    Column("dynamics", "", "only with --lyapunov: periodic, quasi-periodic or chaotic (most of the samples)"),
)
SWEEP_CSV = OutputFile("sweep.csv", "ies sweep --out DIR", "One row per eta of the grid. Amplitudes are averaged over the "
                       "samples (the repetitions); the scattering columns are NaN-aware averages.", (
    Column("eta", "-", "eta = Omega/omega* of the grid point, the frequency the holds were measured at"),
    Column("mean", "a/a_noabs*", "the samples' mean amplitude over the hold, averaged"),
    Column("mean_lo", "a/a_noabs*", "the smallest sample of `mean`"),
    Column("mean_hi", "a/a_noabs*", "the largest sample of `mean`"),
    Column("max", "a/a_noabs*", "the largest amplitude of the hold, averaged over the samples"),
    Column("max_lo", "a/a_noabs*", "the smallest sample of `max`"),
    Column("max_hi", "a/a_noabs*", "the largest sample of `max`"),
    Column("cv", "-", "std/mean of the per-period amplitudes over the hold, averaged (the regime measure)"),
    Column("impacts_per_period", "-", "contact onsets at either wall per excitation period, averaged"),
    Column("regime", "", "APR (cv <= 0.1), SMR (cv > 0.1) or linear (no contact)"),
    *NATURE,
    *SCATTERING))
#: sweep.csv's columns: without --lyapunov (also the columns of a response study's sweeps.csv), and with it
NATURE_COLUMNS = tuple(c.name for c in NATURE)
SWEEP_COLUMNS = tuple(name for name in SWEEP_CSV.names if name not in NATURE_COLUMNS)


def sweep_columns(result: SweepResult) -> tuple[str, ...]:
    """sweep.csv's columns of a frequency response: SWEEP_CSV's, the NATURE columns only when it measured them."""
    return SWEEP_CSV.names if result.dynamics is not None else SWEEP_COLUMNS
OVERVIEW_CSV = OutputFile("overview.csv", "ies overview --out DIR; response studies", "One row per excitation level; "
                          "the scattering columns are taken at `eta_resonant_mean`.", (
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("resonant_mean", "a/a_noabs*", "the resonant level: the largest repetition-averaged mean amplitude over eta "
           "(Sect. 5.3)"),
    Column("resonant_mean_lo", "a/a_noabs*", "the smallest repetition sample at the resonant eta (lo <= value)"),
    Column("resonant_mean_hi", "a/a_noabs*", "the largest repetition sample at the resonant eta (value <= hi)"),
    Column("resonant_max", "a/a_noabs*", "the largest repetition-averaged max amplitude over eta"),
    Column("resonant_max_lo", "a/a_noabs*", "the smallest sample at its eta"),
    Column("resonant_max_hi", "a/a_noabs*", "the largest sample at its eta"),
    Column("eta_resonant_mean", "-", "where the resonant mean is reached"),
    Column("eta_resonant_max", "-", "where the resonant max is reached"),
    Column("impacts_per_period", "-", "contact onsets per period at `eta_resonant_mean`"),
    Column("regime", "", "the regime at `eta_resonant_mean` (APR, SMR, linear): Fig. 6's labels"),
    Column("a_base_m", "m", "the base amplitude a_base"),
    Column("resonant_mean_se", "a/a_noabs*", "standard error of the resonant mean (samples at its eta; NaN for one)"),
    Column("resonant_max_se", "a/a_noabs*", "standard error of the resonant max"),
    *SCATTERING))
#: overview.csv: one row per excitation level (`overview_data`)
OVERVIEW_COLUMNS = OVERVIEW_CSV.names
SWEEP_JSON = OutputFile("sweep.json", "ies sweep --out DIR, also --json", "The arrays of sweep.csv (over eta) and:", (
    Column("level", "a_base/a_base*", "the excitation level"),
    Column("a_base", "m", "the base amplitude"),
    Column("a_noabs", "m", "a_noabs*, the linear resonant amplitude at this excitation (nominal D*)"),
    Column("mean_std, max_std", "a/a_noabs*", "standard deviation over the samples, per eta"),
    Column("regime_per_eta", "", "the `regime` column"),
    Column("lyapunov_samples", "-", "with --lyapunov: the exponents of every visit of each eta (visits x eta; NaN "
           "where an eta has fewer visits)"),
    Column("resonant_mean, resonant_max", "a/a_noabs*", "the largest mean and max over eta"),
    Column("eta_resonant_mean, eta_resonant_max", "-", "where they are reached"),
    Column("regime", "", "the regime at `eta_resonant_mean`"),
    Column("resonant_mean_samples, resonant_max_samples", "a/a_noabs*", "the samples at the resonant eta (their "
           "average is the resonant level)"),
    Column("mean_samples, max_samples, cv_samples, impacts_samples", "", "samples x eta"),
    Column("n_samples, n_runs", "-", "repetition samples and runs"),
    Column("wall_time_s", "s", "wall time"),
    Column("protocol", "", "eta_start, eta_stop, n_eta, sequence, wait and hold (s), perturbation (relative "
           "half-width), perturb, repetition, integrator, dt_scale, start"),
    Column("regime_cv_threshold", "-", "0.1"),
    Column("seed, reps", "-", "the random seed and the number of runs"),
    Column("model", "", "the modal model's source"),
    Column("impactor", "", "mass_kg, g_m, k_H_N_per_m1p5, contact_law (hertz or hertz-damped), r_cont, friction (mu), "
           "k_t_N_per_m; null without impactor"),
    Column("D1", "-", "damping ratio of mode 1"),
    Column("significant_impacts_per_period, restitution, restitution_wall, higher_mode_energy_share, "
           "higher_mode_energy_share_mean", "-", "arrays over eta, as in sweep.csv"),
    Column("dissipation", "", "fundamental, higher_modes, contact, friction (shares of the input), input (W), "
           "balance_error; arrays over eta"),
))
OVERVIEW_JSON = OutputFile("overview.json", "ies overview --out DIR, also --json", "", (
    Column("levels", "a_base/a_base*", "the `level` column; the other columns of overview.csv as lists"),
    Column("dissipation", "", "as in sweep.json, per level"),
    Column("sweeps", "", "each level's sweep.json object"),
    Column("reps, seed", "-", "runs per level, random seed"),
    Column("model", "", "the modal model's source"),
    Column("wall_time_s", "s", "wall time"),
))

def _scattering_column(column: str) -> str:
    """The `sim.stepped_sine.measures.SCATTERING_MEASURES` name of a SCATTERING_COLUMNS column."""
    return "input_power" if column == "input_power_W" else column


def sweep_rows(result: SweepResult) -> list[list[Any]]:
    """The rows of sweep.csv (`sweep_columns`) of one frequency response."""
    n = result.eta.size
    natures = {"lyapunov_per_period": result.lyapunov_per_period, "dynamics": result.dynamics}
    columns = [result.regime_per_eta if name == "regime" else natures[name] if name in natures else
               result.scattering.get(_scattering_column(name), [float("nan")] * n) if name in SCATTERING_COLUMNS else
               getattr(result, name) for name in sweep_columns(result)]
    return [list(row) for row in zip(*columns)]


def overview_data(levels: Sequence[float], results: Sequence[SweepResult]) -> dict[str, list]:
    """The resonant levels (Sect. 5.3) of one frequency response per excitation level, as lists by key: the
    OVERVIEW_COLUMNS ("levels" for the column "level"); spreads from `SweepResult.resonant_spread`; the
    scattering measures at the resonant mean's eta."""
    spread = {name: [r.resonant_spread(name) for r in results] for name in ("mean", "max")}
    return {
        "levels": [float(level) for level in levels],
        "resonant_mean": [r.resonant_mean for r in results],
        "resonant_max": [r.resonant_max for r in results],
        "resonant_mean_lo": [s[0] for s in spread["mean"]],
        "resonant_mean_hi": [s[1] for s in spread["mean"]],
        "resonant_max_lo": [s[0] for s in spread["max"]],
        "resonant_max_hi": [s[1] for s in spread["max"]],
        "resonant_mean_se": [s[2] for s in spread["mean"]],
        "resonant_max_se": [s[2] for s in spread["max"]],
        "a_base_m": [r.a_base for r in results],
        "eta_resonant_mean": [r.eta_resonant_mean for r in results],
        "eta_resonant_max": [r.eta_resonant_max for r in results],
        "regime": [r.regime for r in results],
        "impacts_per_period": [float(r.impacts_per_period[r.eta == r.eta_resonant_mean][0]) for r in results],
        **{column: [_at_resonance(r, _scattering_column(column)) for r in results] for column in SCATTERING_COLUMNS},
    }


def _at_resonance(result: SweepResult, name: str) -> float:
    """A scattering measure of the frequency response at its resonant mean's eta (NaN if it has none)."""
    values = result.scattering.get(name)
    return float(values[result.eta == result.eta_resonant_mean][0]) if values is not None else float("nan")


def dissipation_key(data: dict[str, list]) -> dict[str, list]:
    """The JSON key "dissipation" of `ies overview` from `overview_data` (as `sim.stepped_sine.protocol.scattering_keys`)."""
    return scattering_keys({_scattering_column(column): data[column] for column in SCATTERING_COLUMNS})["dissipation"]


def overview_rows(data: dict[str, list]) -> list[list[Any]]:
    """The rows of overview.csv (OVERVIEW_COLUMNS) of `overview_data`."""
    return [list(row) for row in zip(*(data["levels" if name == "level" else name] for name in OVERVIEW_COLUMNS))]


def overview_text(data: dict[str, list]) -> str:
    """The table `ies overview` prints: resonant mean and max per level, where they occur, impacts, regime."""
    lines = [f"{'level':>7} {'res.mean':>9} {'res.max':>9} {'eta(mean)':>9} {'imp/T':>6}  regime"]
    for i, level in enumerate(data["levels"]):
        lines.append(f"{level:7.3f} {data['resonant_mean'][i]:9.4f} {data['resonant_max'][i]:9.4f} "
                     f"{data['eta_resonant_mean'][i]:9.4f} {data['impacts_per_period'][i]:6.2f}  {data['regime'][i]}")
    return "\n".join(lines)


def scattering_text(data: dict[str, list]) -> str:
    """Per level, at the resonant eta: all and significant impacts per period, r from the tip and from the wall,
    the energy share of modes 2..N after impacts and the dissipation shares (Sect. 5.5, Appendix D)."""
    lines = [f"{'level':>7} {'imp/T':>6} {'sig/T':>6} {'r_tip':>6} {'r_wall':>6} {'E2..N':>6} {'D_1':>6} {'D_2..N':>6}  regime"]
    for i, level in enumerate(data["levels"]):
        lines.append(f"{level:7.3f} {data['impacts_per_period'][i]:6.2f} {data['significant_impacts_per_period'][i]:6.2f} "
                     f"{data['restitution'][i]:6.3f} {data['restitution_wall'][i]:6.3f} "
                     f"{data['higher_mode_energy_share'][i]:6.3f} {data['dissipation_fundamental'][i]:6.3f} "
                     f"{data['dissipation_higher_modes'][i]:6.3f}  {data['regime'][i]}")
    return "\n".join(lines)


def series_text(series: list[tuple[str, dict[str, list]]]) -> str:
    """Figs. 11 and C.1's table: per level, the resonant mean of each value of the series, and the shares (%) of the
    input dissipated in the contact, by friction, in mode 1 and in modes 2..N at the resonant eta (Sect. 5.5)."""
    width = 28
    head = f"{'level':>7} " + " ".join(f"{label:>{width}}" for label, _ in series)
    lines = [head, f"{'':>7} " + " ".join(f"{'mean cont/fric/D_1/D_2..N':>{width}}" for _ in series)]
    for level in series[0][1]["levels"]:
        cells = []
        for _, data in series:
            if level not in data["levels"]:
                cells.append(f"{'-':>{width}}")
                continue
            at = data["levels"].index(level)
            shares = "/".join(f"{100 * data[key][at]:.1f}" for key in ("dissipation_contact", "dissipation_friction",
                                                                        "dissipation_fundamental", "dissipation_higher_modes"))
            cells.append(f"{data['resonant_mean'][at]:.3f} {shares}%")
        lines.append(f"{level:7.3f} " + " ".join(f"{c:>{width}}" for c in cells))
    return "\n".join(lines)


def optimum_line(data: dict[str, list]) -> str:
    """Where the resonant mean level is lowest (the optimum, Sect. 5.3) and the reductions there, 1 / level (the
    levels are normalised by the linear resonant amplitude a_noabs* at the same excitation)."""
    i = min(range(len(data["levels"])), key=lambda k: data["resonant_mean"][k])
    return (f"optimum: a_base/a_base* = {data['levels'][i]:g} ({data['regime'][i]}), resonant mean "
            f"{data['resonant_mean'][i]:.4f} and max {data['resonant_max'][i]:.4f} of a_noabs*: reduced "
            f"{1 / data['resonant_mean'][i]:.0f}x (mean) and {1 / data['resonant_max'][i]:.0f}x (max); the paper: "
            f"{PAPER_OPTIMUM_LEVEL:g}, {PAPER_REDUCTION_MEAN:.0f}x and {PAPER_REDUCTION_MAX:.0f}x")
