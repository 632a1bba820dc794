"""The 3D solid model (sim/hosts/solid.py, seed paper Sect. 3.1) against analytic beam theory, its input checks, and its
mode selection. References: the Euler-Bernoulli cantilever (beta_n L roots of cos cosh = -1, tip value 2/sqrt(m)) and
the exact Timoshenko cantilever (closed-form solution of the two coupled ODEs, frequencies from its 4 x 4 boundary
determinant, mode shapes from its null vector), neither of which uses our FE code."""
import math

import numpy as np
import pytest
from scipy.integrate import quad
from scipy.optimize import brentq

pytest.importorskip("skfem")

from sim.common.errors import SimulationInputError  # noqa: E402
from sim.hosts.solid import (SolidGeometry, SolidMaterial, select_x_bending, solid_mesh, solid_modal_model,  # noqa: E402
                       solve_solid_modes)

E, NU, RHO = 207e9, 0.3, 7843.0
EB_ROOTS = np.array([1.8751040687, 4.6940911330, 7.8547574382, 10.9955407349, 14.1371683910])


def cantilever(length: float, width_x: float, width_y: float) -> SolidGeometry:
    """A uniform cantilever clamped at z = 0: no block, neck, cavity; values on the axis at the free end."""
    return SolidGeometry(free_length=length, section_x=width_x, section_y=width_y, neck_length=0.0, cavity_z=0.0,
                         groove_depth=0.0, block_edge=0.0, measurement_below_contact=0.0, measurement_on_face=False)


class TimoshenkoCantilever:
    """Exact clamped-free Timoshenko beam bending in x: EI theta'' + kGA (w' - theta) + rho I w^2 theta = 0,
    kGA (w'' - theta') + rho A w^2 w = 0; w = theta = 0 at z = 0, EI theta' = kGA (w' - theta) = 0 at z = L.
    Shear coefficient: Cowper's solid rectangle 10 (1 + nu) / (12 + 11 nu)."""

    def __init__(self, length, width_x, width_y):
        self.L = length
        self.A = width_x * width_y
        self.I = width_y * width_x**3 / 12
        self.kGA = 10 * (1 + NU) / (12 + 11 * NU) * E / (2 * (1 + NU)) * self.A

    def _basis(self, omega):
        # w = sum c_k f_k(z), theta = sum c_k g_k(z) with f = (cosh az, sinh az, cos bz, sin bz)
        EI, kGA, rA, rI = E * self.I, self.kGA, RHO * self.A * omega**2, RHO * self.I * omega**2
        # EI kGA s^2 + (kGA rI + rA EI) s + rA (rI - kGA) = 0, s = lambda^2
        s = np.roots([EI * kGA, kGA * rI + rA * EI, rA * (rI - kGA)])
        a, b = math.sqrt(max(s.real)), math.sqrt(-min(s.real))
        c = rA / kGA
        ka, kb = a + c / a, b - c / b
        f = lambda z: np.array([np.cosh(a * z), np.sinh(a * z), np.cos(b * z), np.sin(b * z)])  # noqa: E731
        df = lambda z: np.array([a * np.sinh(a * z), a * np.cosh(a * z), -b * np.sin(b * z), b * np.cos(b * z)])  # noqa: E731
        g = lambda z: np.array([ka * np.sinh(a * z), ka * np.cosh(a * z), -kb * np.sin(b * z), kb * np.cos(b * z)])  # noqa: E731
        dg = lambda z: np.array([ka * a * np.cosh(a * z), ka * a * np.sinh(a * z), -kb * b * np.cos(b * z),  # noqa: E731
                                 -kb * b * np.sin(b * z)])
        return f, df, g, dg

    def _matrix(self, omega):
        f, df, g, dg = self._basis(omega)
        L = self.L
        return np.array([f(0.0), g(0.0), dg(L), df(L) - g(L)])

    def _det(self, omega):
        m = self._matrix(omega)
        return np.linalg.det(m / np.abs(m).max(axis=1, keepdims=True))

    def modes(self, n):
        """(f in Hz, tip value, participation) of the n lowest modes, mass-normalised with rho A w^2 + rho I theta^2."""
        eb = EB_ROOTS[0] ** 2 / self.L**2 * math.sqrt(E * self.I / (RHO * self.A))
        grid = np.linspace(0.5 * eb, 80 * eb, 20000)
        values = np.array([self._det(w) for w in grid])
        out = []
        for k in np.flatnonzero(np.sign(values[:-1]) != np.sign(values[1:]))[:n]:
            omega = brentq(self._det, grid[k], grid[k + 1], xtol=1e-12 * grid[k])
            coef = np.linalg.svd(self._matrix(omega))[2][-1]
            f, _, g, _ = self._basis(omega)
            norm = quad(lambda z: RHO * self.A * (coef @ f(z)) ** 2 + RHO * self.I * (coef @ g(z)) ** 2, 0, self.L,
                        epsabs=0, epsrel=1e-12, limit=200)[0]
            part = RHO * self.A * quad(lambda z: coef @ f(z), 0, self.L, epsabs=0, epsrel=1e-12, limit=200)[0]
            tip = coef @ f(self.L)
            sign = np.sign(tip)
            out.append((omega / (2 * np.pi), abs(tip) / math.sqrt(norm), sign * part / math.sqrt(norm)))
        return np.array(out).T


@pytest.fixture(scope="module")
def stocky_modes():
    """L/h = 40 cantilever, 10 mm (x) by 8 mm (y): y-bending below x-bending; 5 mm elements across, 10 mm along."""
    geometry = cantilever(0.4, 0.010, 0.008)
    solid = solid_mesh(geometry, SolidMaterial(E, NU, RHO), element_size=0.01)
    return geometry, solve_solid_modes(solid, n_modes=5)


def test_timoshenko_cantilever_frequencies_tip_values_participation(stocky_modes):
    geometry, modes = stocky_modes
    f_ref, tip_ref, part_ref = TimoshenkoCantilever(0.4, 0.010, 0.008).modes(5)
    model = solid_modal_model(modes)
    np.testing.assert_allclose(model.frequencies_hz, f_ref, rtol=5e-3)
    np.testing.assert_allclose(model.phi_tip, tip_ref, rtol=5e-3)
    np.testing.assert_allclose(model.participation, part_ref, rtol=5e-3, atol=1e-3 * abs(part_ref[0]))
    # measured: f +0.23..+0.32 %, tip +0.06..+0.10 %, participation -0.06 %. The 3D model is stiffer by about
    # 0.15 % x (10 mm / L) at any mesh: the clamped root face also stops the Poisson contraction there.
    assert np.max(np.abs(model.frequencies_hz / f_ref - 1)) < 3.5e-3
    assert np.max(np.abs(model.phi_tip / tip_ref - 1)) < 1.5e-3


def test_beam_mass_and_floor_values_for_eq_10_and_friction(stocky_modes):
    """The modal file's keys of the damped law and friction: the free length's mass (rho times volume) and, without
    a cavity, the floor values at the free end's centre, which are the cantilever's tip values (Timoshenko)."""
    _, modes = stocky_modes
    model = solid_modal_model(modes)
    assert model.beam_mass == pytest.approx(RHO * 0.4 * 0.010 * 0.008, rel=1e-12)
    np.testing.assert_allclose(model.phi_floor, TimoshenkoCantilever(0.4, 0.010, 0.008).modes(5)[1], rtol=5e-3)


def test_euler_bernoulli_slender_cantilever():
    """L/h = 80: Euler-Bernoulli applies (Timoshenko's correction of mode 5 is 0.3 %); tip value 2/sqrt(rho A L).
    The section is 5 x 4 mm: a square one would make x- and y-bending degenerate, and their computed eigenvectors
    arbitrary mixtures that no symmetry test takes for x-bending."""
    L, h = 0.4, 0.005
    solid = solid_mesh(cantilever(L, h, 0.004), SolidMaterial(E, NU, RHO), element_size=0.01)
    model = solid_modal_model(solve_solid_modes(solid, n_modes=5))
    A, I = h * 0.004, 0.004 * h**3 / 12
    f_eb = EB_ROOTS**2 / L**2 * math.sqrt(E * I / (RHO * A)) / (2 * np.pi)
    np.testing.assert_allclose(model.frequencies_hz, f_eb, rtol=5e-3)
    np.testing.assert_allclose(model.phi_tip, 2 / math.sqrt(RHO * A * L), rtol=5e-3)
    # effective masses of the EB cantilever: 0.6131, 0.1883, 0.0647, 0.0331, 0.0200 of the beam's mass
    np.testing.assert_allclose(model.participation**2 / (RHO * A * L), [0.6131, 0.1883, 0.0647, 0.0331, 0.0200],
                               rtol=1e-2)


def test_mode_selection_takes_x_bending_and_says_why_others_not(stocky_modes):
    _, modes = stocky_modes
    assert np.all(modes.symmetric_y > 0.999) and np.all(modes.antisymmetric_x > 0.999)
    assert np.all(modes.kinetic_x_share > 0.95)
    # y-bending (8 mm < 10 mm) lies below each x-bending mode, torsion and axial modes in between
    assert modes.selected[0] == 1
    assert any("y-participation" in line for line in modes.rejected)
    assert all(line.startswith("mode ") for line in modes.rejected)
    skipped = set(range(modes.selected[-1])) - set(modes.selected)
    assert len(modes.rejected) == len(skipped)
    # mass normalisation and the walls of a section without cavity: the outer x-faces at the free end
    phi = modes.phi
    np.testing.assert_allclose(phi.T @ (modes.solid.M @ phi), np.eye(5), atol=1e-9)
    left, right = modes.wall_values()
    assert np.all(left + right > 0)


def test_select_x_bending_by_participation_alone():
    participation = np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [1e-12, 1e-13, 1e-12], [0.1, 0.0, 0.5],
                              [-0.3, 0.01, 0.0], [0.2, 0.0, 0.0]])
    chosen, rejected = select_x_bending(participation, None, n_modes=2)
    assert chosen.tolist() == [1, 4]
    assert rejected == ["mode 1: y-participation 1 against x 0", "mode 3: no translational participation",
                        "mode 4: z-participation 0.5 against x 0.1"]
    chosen, rejected = select_x_bending(participation, np.array([True, True, True, True, False, True]), n_modes=3)
    assert chosen.tolist() == [1, 5]
    assert "mode 5: not x-bending symmetric" in rejected


def test_patch_average_and_user_points(stocky_modes):
    geometry, modes = stocky_modes
    point = modes.wall_values(height=0.39)
    patch = modes.wall_values(height=0.39, patch_radius=1e-3)[0]
    assert np.allclose(patch, point[0], rtol=2e-3) and not np.allclose(patch, point[0], rtol=1e-9, atol=0)
    with pytest.raises(SimulationInputError, match="outside the solid"):
        modes.wall_values(patch_radius=1e-3)  # the circle pokes out of the free end
    point = modes.wall_values()
    left, right = modes.wall_values(points=((-0.005, 0.0, 0.4), (0.005, 0.001, 0.4)))
    assert np.allclose(left, point[0]) and not np.allclose(right, point[1], rtol=1e-9, atol=0)
    with pytest.raises(SimulationInputError, match="outside the solid"):
        modes.wall_values(points=((-0.02, 0.0, 0.4), (0.005, 0.0, 0.4)))


@pytest.mark.parametrize("changes, message", [
    (dict(cavity_x=0.030), "cavity .* must be narrower than the section"),
    (dict(cavity_y=0.022), "must be narrower than the section"),
    (dict(section_x=-0.028), "section_x must be a non-negative length"),
    (dict(free_length=0.0), "free_length must be positive"),
    (dict(groove_width=0.017), "groove .* narrower than the cavity"),
    (dict(neck_width_y=0.03), "neck must be positive and no wider"),
    (dict(neck_length=0.39), "must fit into the free length"),
    (dict(block_edge=0.02), "block must be wider"),
    (dict(sphere_radius=0.003), "sphere must be wider than the groove"),
    (dict(clamp="bolts"), "clamp must be one of"),
    (dict(free_length=float("nan")), "free_length must be a non-negative length"),
])
def test_geometry_that_does_not_fit_is_one_line(changes, message):
    with pytest.raises(SimulationInputError, match=message) as info:
        SolidGeometry(**changes)
    assert "\n" not in str(info.value)


def test_bad_mesh_and_material_inputs():
    with pytest.raises(SimulationInputError, match="element size must lie in"):
        solid_mesh(element_size=0.02)
    with pytest.raises(SimulationInputError, match="unknown element"):
        solid_mesh(cantilever(0.1, 0.01, 0.01), element_size=0.01, element="tet10")
    with pytest.raises(SimulationInputError, match="material needs"):
        SolidMaterial(nu=0.5)
    from sim.hosts.solid import solid_rig_model

    with pytest.raises(SimulationInputError, match="unknown mesh level 'huge'; choose one of coarse, medium, fine"):
        solid_rig_model(mesh="huge")


def test_missing_scikit_fem_is_one_line(monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "skfem", None)
    with pytest.raises(SimulationInputError, match=r"pip install '\.\[solid\]'"):
        solid_mesh(cantilever(0.1, 0.01, 0.01), element_size=0.01)


def test_rig_geometry_defaults_match_the_beam_model():
    from sim.hosts.rig import JOINT_SPRING_PARAMETERS, RigGeometry, rig_modes

    g, rig = SolidGeometry(), RigGeometry()
    assert g.contact_height == pytest.approx(rig.contact_height, abs=1e-12)
    assert g.measurement_height == pytest.approx(rig.measurement_height, abs=1e-12)
    assert g.contact_height - g.floor_height == pytest.approx(math.sqrt(0.00792**2 - 0.004**2))
    beam = rig_modes(JOINT_SPRING_PARAMETERS)
    assert RHO * g.beam_volume == pytest.approx(beam.beam_mass, rel=1e-9)


def test_rig_mesh_is_symmetric_conforming_and_weighs_what_the_geometry_does():
    g = SolidGeometry()
    solid = solid_mesh(g, element_size=0.016)
    block = g.block_edge**3
    assert solid.total_mass == pytest.approx(RHO * (block + g.beam_volume), rel=1e-12)
    assert np.all(solid.mirror_x >= 0) and np.all(solid.mirror_y >= 0)
    # the contact and measurement points are grid nodes: the interpolation is the nodal value
    locs = solid.basis.doflocs[:, solid.free]
    for point in (g.wall_point("left"), g.wall_point("right"), g.measurement_point):
        assert np.min(np.linalg.norm(locs.T - point, axis=1)) < 1e-12


def test_quarter_model_is_the_full_models_x_bending_class():
    """The quarter model with the mirror conditions gives the full model's x-bending modes: frequencies, values at
    both walls (patch average across y = 0), tip and participation, to round-off; a quarter of the DOFs."""
    g = SolidGeometry()
    full, quarter = (solid_modal_model(solve_solid_modes(solid_mesh(g, element_size=0.016, symmetry=s), n_modes=9),
                                       patch_radius=0.5e-3) for s in ("full", "quarter"))
    for key in ("frequencies_hz", "phi_wall_left", "phi_wall_right", "phi_tip", "participation"):
        np.testing.assert_allclose(getattr(quarter, key), getattr(full, key), rtol=1e-8, err_msg=key)
    with pytest.raises(SimulationInputError, match="unknown symmetry 'half'"):
        solid_mesh(g, element_size=0.016, symmetry="half")


def test_stretched_grid_follows_the_geometry():
    """A grid built for one neck and stretched onto another has the same element count, weighs what the new
    geometry weighs, and its frequencies differ from the new geometry's own grid by mesh error only."""
    g0 = SolidGeometry()
    g1 = SolidGeometry(neck_length=0.12, neck_width_y=0.013)
    stretched = solid_mesh(g1, element_size=0.016, symmetry="quarter", grid_from=g0)
    own = solid_mesh(g1, element_size=0.016, symmetry="quarter")
    assert stretched.mesh.t.shape[1] == solid_mesh(g0, element_size=0.016, symmetry="quarter").mesh.t.shape[1]
    assert stretched.total_mass == pytest.approx(RHO * (g1.block_edge**3 + g1.beam_volume), rel=1e-12)
    f_stretched = solve_solid_modes(stretched, n_modes=4).frequencies_hz
    f_own = solve_solid_modes(own, n_modes=4).frequencies_hz
    np.testing.assert_allclose(f_stretched, f_own, rtol=2e-3)
    with pytest.raises(SimulationInputError, match="do not correspond one to one"):
        solid_mesh(SolidGeometry(neck_length=0.0), element_size=0.016, grid_from=g0)


def _neck_beam(neck_length: float, neck_width_y: float) -> SolidGeometry:
    """A 400 mm beam of the rig's section with a y-neck at its clamped root, no block or cavity."""
    return SolidGeometry(cavity_z=0.0, groove_depth=0.0, block_edge=0.0, neck_length=neck_length,
                         neck_width_y=neck_width_y)


def test_updating_recovers_a_known_neck():
    """Frequencies f1..f4, f9 of a known neck (85 x 12 mm) as targets: the updating from another neck finds it
    (same element counts, so the targets are reachable exactly) and reports the errors, mass and modal ratios."""
    from sim.hosts.solid import update_solid_geometry

    truth = _neck_beam(0.085, 0.012)
    f = solve_solid_modes(solid_mesh(truth, element_size=0.016, symmetry="quarter"), 9).frequencies_hz
    result = update_solid_geometry(("neck_length", "neck_width_y"), _neck_beam(0.095, 0.014), mesh=0.016,
                                   targets_hz=f[[0, 1, 2, 3, 8]])
    assert result.geometry.neck_length == pytest.approx(0.085, rel=1e-6)
    assert result.geometry.neck_width_y == pytest.approx(0.012, rel=1e-6)
    assert np.max(np.abs(result.frequency_errors)) < 1e-8 and abs(result.f9_error) < 1e-8
    assert result.beam_mass == pytest.approx(RHO * truth.beam_volume, rel=1e-9) and result.on_bounds == ()
    assert 0 < result.modal_mass_ratio < 0.1 and 0.9 < result.phi_tip_over_phi_c < 1.0


@pytest.mark.parametrize("kwargs, message", [
    (dict(free=("sphere_radius",)), "free dimensions must be among"),
    (dict(free=()), "free dimensions must be among"),
    (dict(targets_hz=(117.4, 886.0)), "five positive targets"),
    (dict(mesh="huge"), "unknown mesh level 'huge'"),
])
def test_updating_bad_input_is_one_line(kwargs, message):
    from sim.hosts.solid import update_solid_geometry

    with pytest.raises(SimulationInputError, match=message):
        update_solid_geometry(**kwargs)


def test_wall_values_are_continuous_and_rise_towards_the_open_end():
    """From the sphere-centre height to the wall's top edge the x-values of the higher modes rise smoothly (the
    cavity walls are cantilevered plates above the floor), and the more so the higher the mode."""
    g = SolidGeometry()
    modes = solve_solid_modes(solid_mesh(g, element_size=0.016, symmetry="quarter"), n_modes=9)
    heights = np.linspace(g.contact_height, g.free_length, 41)
    values = np.array([np.mean(modes.wall_values(height=z), axis=0) for z in heights])  # (41, 9)
    ratio = values / values[0]
    assert np.max(np.abs(np.diff(ratio, axis=0))) < 0.06  # 0.25 mm steps: no jumps at element faces
    assert np.all(np.diff(ratio[:, 1:], axis=0) > 0)  # modes 2-9 rise monotonically
    assert np.all(np.diff(ratio[-1]) > -0.05) and ratio[-1, 8] > 1.5 * ratio[-1, 1] > 1.5


@pytest.mark.slow
def test_stored_updated_geometry_reproduces_its_fit():
    """sim.hosts.solid.UPDATED_SOLID_GEOMETRY still gives what its comment states (coarse mesh, E = 207 GPa): f1..f4 of
    Table A.1 within +0.004, -1.36, +0.63, +0.12 %, f9 = 20.41 kHz, beam 1.545 kg, m_a phi_c1^2 = 3.57 %."""
    from sim.hosts.rig import F_MEASURED_HZ
    from sim.hosts.solid import UPDATED_SOLID_GEOMETRY
    from sim.model.system import SPHERE_MASS

    g = UPDATED_SOLID_GEOMETRY
    modes = solve_solid_modes(solid_mesh(g, element_size=0.008, symmetry="quarter"), 9)
    errors = modes.frequencies_hz[:4] / np.array(F_MEASURED_HZ) - 1
    np.testing.assert_allclose(100 * errors, [0.004, -1.358, 0.627, 0.117], atol=2e-3)
    assert modes.frequencies_hz[8] == pytest.approx(20410, abs=1)
    assert RHO * g.beam_volume == pytest.approx(1.545, abs=5e-4)
    assert SPHERE_MASS * np.mean(modes.wall_values(), axis=0)[0] ** 2 == pytest.approx(0.0357, abs=1e-4)


def test_solid_and_its_timoshenko_counterpart_like_for_like():
    """The same rig (the updated solid geometry without the block, clamped at its root section, E = 207 GPa) as a
    solid (medium mesh, quarter) and as the Timoshenko beam of sim.hosts.rig. Bands: the issue's claims where the beam
    theory's assumptions hold (f1..f9 within 0.4 %, the contact values of modes 1-5 within 2 %; mesh-converged at
    1.8 mm: 0.36 % and 1.2 %). Above them the physics of the open cavity: its walls are plates, more compliant than
    the tube's plane sections, so the solid's contact values of modes 6-9 exceed the beam's, and more so at
    higher frequency: the excess of modes 8-9 is at least twice the larger of modes 6-7 (a wall compliance felt
    as f^2 gives (f8/f6)^2 = 2.6; converged 6.5-7.4 % against 2.2-2.4 %). Without the neck the 3D clamped root face (it also fixes the
    section's warping and contraction) makes every solid frequency higher than the beam's."""
    from dataclasses import replace

    from sim.hosts.solid import UPDATED_SOLID_GEOMETRY, compare_with_timoshenko

    rig = replace(UPDATED_SOLID_GEOMETRY, block_edge=0.0, measurement_on_face=False)
    c = compare_with_timoshenko(rig, SolidMaterial(E, NU, RHO), "medium")
    assert np.max(np.abs(c["f_rel_diff"])) < 0.004
    ratio = np.array(c["phi_c_ratio"])
    assert np.max(np.abs(ratio[:5] - 1)) < 0.02
    assert np.all(ratio[5:] > 1) and min(ratio[7:]) - 1 > 2 * (max(ratio[5:7]) - 1)
    no_neck = compare_with_timoshenko(replace(rig, neck_length=0.0), SolidMaterial(E, NU, RHO), "medium")
    assert np.all(np.array(no_neck["f_rel_diff"]) > 0)
    with pytest.raises(SimulationInputError, match="block_edge = 0"):
        compare_with_timoshenko(UPDATED_SOLID_GEOMETRY)
