"""`ies modes`: the modal model of the host structure (seed paper Sect. 3.1, Eq. 7, Appendix A).

Without --model it shows the built-in model of the seed rig (sim.rig: Timoshenko beam, updated to Table A.1);
with --model FILE a modal-model file (format in sim/modal_file.py). --save writes the shown model as a file.
"""
from __future__ import annotations

import argparse

NAME = "modes"
HELP = "modal model of the host structure: frequencies, damping, mode values, participation (built-in rig or file)"


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--json", action="store_true", help="print one JSON object instead of a table")
    parser.add_argument("--save", metavar="FILE", help="write the model as a modal-model file (.toml)")
    parser.add_argument("--model", metavar="FILE", help="read a modal-model file instead of the built-in seed rig")
    parser.add_argument("--variant", default=None, metavar="NAME",
                        help="updating variant of the built-in rig: joint-spring (default) or effective-modulus")


def describe(model, rig=None) -> dict:
    """The JSON object of `ies modes --json`: the model's arrays plus the derived numbers (SI units)."""
    import numpy as np

    from sim.system import SPHERE_MASS, a_base_star

    phi_c = model.phi_contact
    data = {
        "source": model.source,
        "n_modes": model.n_modes,
        "frequencies_hz": model.frequencies_hz,
        "damping_ratios": model.damping_ratios,
        "phi_wall_left": model.phi_wall_left,
        "phi_wall_right": model.phi_wall_right,
        "phi_tip": model.phi_tip,
        "participation": model.participation,
        "modal_mass_ratio": SPHERE_MASS * phi_c**2,
        "phi_tip_over_phi_c": float(model.phi_tip[0] / phi_c),
        "a_base_star": a_base_star(model),
        "dt": 2.0 * np.pi / (15.0 * float(model.omega[-1])),
        "units": {"frequencies_hz": "Hz", "damping_ratios": "1", "phi": "1/sqrt(kg)", "participation": "sqrt(kg)",
                  "a_base_star": "m", "dt": "s", "modal_mass_ratio": "1 (sphere mass m_a = %g kg)" % SPHERE_MASS},
    }
    if rig is not None:
        data["rig"] = rig.summary()
    return data


def _table(data: dict) -> str:
    lines = [f"modal model: {data['source']}",
             f"{'mode':>4} {'f (Hz)':>11} {'D (%)':>7} {'phi_l':>9} {'phi_r':>9} {'phi_tip':>9} {'phi^T M b':>10}"]
    for j in range(data["n_modes"]):
        lines.append(f"{j + 1:>4} {data['frequencies_hz'][j]:>11.2f} {100 * data['damping_ratios'][j]:>7.3f} "
                     f"{data['phi_wall_left'][j]:>9.4f} {data['phi_wall_right'][j]:>9.4f} {data['phi_tip'][j]:>9.4f} "
                     f"{data['participation'][j]:>10.4f}")
    lines.append("mode values in 1/sqrt(kg), participation in sqrt(kg)")
    lines.append(f"modal mass ratio m_a phi_c^2 = {100 * data['modal_mass_ratio']:.2f} %   "
                 f"phi_tip/phi_c = {data['phi_tip_over_phi_c']:.4f}")
    lines.append(f"a_base* = {data['a_base_star']:.4e} m   ode3 step dt = 2 pi/(15 omega_{data['n_modes']}) = {data['dt']:.4e} s")
    rig = data.get("rig")
    if rig:
        errors = ", ".join(f"{round(100 * e, 4) + 0.0:+.4f} %" for e in rig["f_model_error"])
        p = rig["updated_parameters"]
        joint = p.get("joint_translational_stiffness_N_per_m")
        lines.append(f"updated: E = {p['E_Pa'] / 1e9:.2f} GPa, neck {1e3 * p['neck_length_m']:.2f} mm long, "
                     f"{1e3 * p['neck_width_x_m']:.2f} x {1e3 * p['neck_width_y_m']:.2f} mm (x, y), joint "
                     + ("rigid" if joint is None else f"spring {joint:.4g} N/m"))
        lines.append(f"f1..f4 vs Table A.1: {errors}")
        if "f9_hz" in rig:
            lines.append(f"f9 = {rig['f9_hz']:.0f} Hz (paper's 3D model: {rig['f9_paper_hz']:.0f} Hz)")
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    from sim.errors import SimulationInputError
    from sim.modal_file import load_modal_model, save_modal_model
    from uq.output import dumps

    if args.model:
        if args.variant is not None:
            raise SimulationInputError("--variant selects a built-in rig model; it cannot be used with --model")
        model, rig = load_modal_model(args.model), None
    else:
        from sim.rig import DEFAULT_VARIANT, rig_modes, seed_rig_model, variant_parameters

        variant = args.variant or DEFAULT_VARIANT
        model = seed_rig_model(n_modes=9, variant=variant)
        rig = rig_modes(variant_parameters(variant), n_modes=9)
    data = describe(model, rig)
    if args.save:
        data["saved_to"] = str(save_modal_model(model, args.save))
    print(dumps(data) if args.json else _table(data))
    return 0
