"""The host structure as a 3D solid finite-element modal model, as the seed paper builds it (Sect. 3.1, Fig. 2c:
CalculiX, quadratic hexahedra C3D20): geometry from the rig's dimensions, a structured hexahedral mesh, the
clamped eigenproblem of Eq. 2 solved by shift-invert Lanczos, the x-bending modes picked out, and the modal
model of Eq. 7 (mass-normalised values at the cavity walls and the measurement point, participation phi^T M b).

Model (all SI units; z along the beam from the block's top face to the free end, x the bending direction,
origin on the beam's axis):

* Block: a solid cube (block_edge, default 120 mm) below z = 0, centred on the beam's axis. The paper clamps "the
  faces highlighted in Fig. 2c" of the bolted block (not published). Default clamp "block-faces": the block's lower
  face and its four side faces are fixed, the top face (where the beam enters) is free, so the block adds the local
  elasticity of the beam's root (the joint spring of the beam model, sim/hosts/rig.py) but no modes of its own below
  20 kHz. clamp "lower-face" fixes only the lower face: then the block rocks on it at 4.3-4.8 kHz (coarse mesh,
  E = 207 GPa) and splits the fourth bending mode into two, which the measured FRF (Fig. A.1, a single mode at
  4712 Hz) and the paper's count of nine bending modes up to 19.8 kHz do not show. block_edge = 0 drops the block
  and clamps the beam's root section z = 0 (the uniform-cantilever references use this).
* Neck from z = 0 (neck_length x neck_width_x x neck_width_y), then the main section section_x x section_y up to
  the free end at z = free_length; the open cavity (cavity_x x cavity_y x cavity_z) at the free end and the
  groove (groove_width in y, groove_depth deep, along x over the cavity's length) in its floor. Defaults: the
  built-in beam model's updated geometry (sim.hosts.rig, JOINT_SPRING_PARAMETERS), so the two models compare.
* Mesh: a tensor-product grid of boxes whose grid lines contain every geometric boundary, the contact and
  measurement heights and the mid-planes x = 0, y = 0; boxes in voids (cavity, groove, neck cut, around the
  beam) are removed, so the mesh is conforming and symmetric about x = 0 and y = 0. Beam boxes are at most
  element_size long; in the block they grow geometrically (ratio 1.5) away from the beam. Elements: 20-node
  serendipity hexahedra (scikit-fem ElementHexS2 = CalculiX C3D20) or 27-node Lagrange (ElementHex2), both with
  3 x 3 x 3 Gauss points like C3D20 (exact for boxes). Every element is a box, so its matrices are
  K_e = sum_ij V / (h_i h_j) K_ij and M_e = V M_1 with reference matrices of the unit cube (assembled once
  with scikit-fem): the assembly costs one small dense product per element. symmetry "quarter" meshes x >= 0,
  y >= 0 with the mirror conditions of x-bending: the same x-bending modes as the full mesh (to round-off) at a
  quarter of the DOFs and about a tenth of the time (coarse rig: 7 s instead of 60 s).
* Values: phi_wall_left / phi_wall_right = x-displacement of the mode at the centre of the left (x < 0) and
  right inner wall face at the sphere-centre height (the sphere of radius R resting on the groove's edges:
  sqrt(R^2 - (groove_width/2)^2) above the cavity floor), interpolated with the element's shape functions;
  optionally averaged over a circle of the given radius on the face (e.g. the Hertz contact radius), or at a
  user point. phi_tip: x-displacement at the measurement point measurement_below_contact below the contact
  height, on the beam's outer face x = +section_x/2 (where the accelerometer sits, Fig. 2b) or on its axis.
* Participation phi^T M b with b the unit x-translation of every node, M b of the unclamped mesh restricted to
  the free DOFs (as sim/hosts/rig.py); mass normalisation phi^T M phi = 1; signs per sim/model/system.py: each mode's mean
  wall value is positive.
"""
from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, replace
from functools import lru_cache
from typing import Sequence

import numpy as np
import scipy.sparse
import scipy.sparse.linalg

from sim.common.errors import SimulationInputError
from sim.common.files import to_jsonable
from sim.hosts.rig import (JOINT_SPRING_PARAMETERS, NU_STEEL, RHO_STEEL, ContactHeights, RigGeometry, damping_ratios,
                           rig_host)
from sim.model.system import ModalModel

INSTALL_HINT = "the 3D solid model needs scikit-fem: pip install '.[solid]'"

# Table 1 (host structure): the paper's E_s; the beam model's updating moves it to 215 GPa (sim.hosts.rig)
E_STEEL_PAPER = 207e9

# Target element length along the beam (m) per mesh level; the paper's rule (Sect. 3.1) asks for < 16 mm
MESH_LEVELS = {"coarse": 0.008, "medium": 0.0055, "fine": 0.004}
# The convergence partner of a level: the same mesh with elements this much longer
CONVERGENCE_RATIO = 1.5
BLOCK_GROWTH = 1.5  # element length ratio of neighbouring boxes in the block (away from the beam)
ELEMENT_NAMES = {"hex20": "hex20 (20-node serendipity, CalculiX C3D20)", "hex27": "hex27 (27-node Lagrange)"}
ELEMENTS = tuple(ELEMENT_NAMES)
CLAMPS = ("block-faces", "lower-face")
SYMMETRIES = ("full", "quarter")
_RIG = RigGeometry()


def _require_skfem():
    try:
        import skfem
    except ImportError:
        raise SimulationInputError(INSTALL_HINT) from None
    return skfem


@dataclass(frozen=True)
class SolidGeometry(ContactHeights):
    """Dimensions of the rig's host structure for the 3D model (m); see the module docstring.

    A zero neck_length, cavity_z, groove_depth or block_edge leaves that feature out; measurement_on_face puts
    the measurement point on the outer face x = +section_x/2 (True) or on the axis (False).
    """

    free_length: float = _RIG.free_length
    section_x: float = _RIG.section_x
    section_y: float = _RIG.section_y
    neck_length: float = JOINT_SPRING_PARAMETERS.neck_length
    neck_width_x: float = JOINT_SPRING_PARAMETERS.neck_width_x
    neck_width_y: float = JOINT_SPRING_PARAMETERS.neck_width_y
    cavity_x: float = _RIG.cavity_x
    cavity_y: float = _RIG.cavity_y
    cavity_z: float = _RIG.cavity_z
    groove_depth: float = _RIG.groove_depth
    groove_width: float = _RIG.groove_width
    block_edge: float = _RIG.block_edge
    sphere_radius: float = _RIG.sphere_radius
    measurement_below_contact: float = _RIG.measurement_below_contact
    measurement_on_face: bool = True
    clamp: str = "block-faces"

    def __post_init__(self) -> None:
        if self.clamp not in CLAMPS:
            raise SimulationInputError(f"solid geometry: clamp must be one of {', '.join(CLAMPS)}, got {self.clamp!r}")
        for name, value in asdict(self).items():
            if name in ("measurement_on_face", "clamp"):
                continue
            if not (isinstance(value, (int, float)) and math.isfinite(value) and value >= 0):
                raise SimulationInputError(f"solid geometry: {name} must be a non-negative length in m, got {value!r}")
        for name in ("free_length", "section_x", "section_y"):
            if getattr(self, name) <= 0:
                raise SimulationInputError(f"solid geometry: {name} must be positive, got {getattr(self, name)!r} m")
        fits = [
            (self.neck_length == 0 or (0 < self.neck_width_x <= self.section_x and 0 < self.neck_width_y
                                       <= self.section_y), "the neck must be positive and no wider than the section"),
            (self.cavity_z == 0 or (0 < self.cavity_x < self.section_x and 0 < self.cavity_y < self.section_y),
             f"the cavity ({1e3 * self.cavity_x:g} x {1e3 * self.cavity_y:g} mm) must be narrower than the section "
             f"({1e3 * self.section_x:g} x {1e3 * self.section_y:g} mm) in x and y"),
            (self.groove_depth == 0 or (self.cavity_z > 0 and 0 < self.groove_width < self.cavity_y),
             "the groove needs a cavity and must be narrower than the cavity in y"),
            (self.neck_length + self.cavity_z + self.groove_depth < self.free_length,
             "neck, cavity and groove must fit into the free length"),
            (self.block_edge == 0 or self.block_edge > max(self.section_x, self.section_y),
             "the block must be wider than the beam's section"),
            (self.cavity_z == 0 or self.contact_below_top > 0,
             "the sphere centre must lie inside the cavity (cavity deeper than the sphere's resting height)"),
        ]
        for ok, message in fits:
            if not ok:
                raise SimulationInputError(f"solid geometry does not fit: {message}")
        if self.cavity_z > 0 and self.sphere_radius <= 0.5 * self.groove_width:
            raise SimulationInputError("solid geometry does not fit: the sphere must be wider than the groove "
                                       "(it rests on the groove's edges)")
        if self.measurement_height <= 0 or (not self.measurement_on_face and self.cavity_z > 0
                                            and self.measurement_height >= self.floor_height - self.groove_depth):
            raise SimulationInputError("solid geometry does not fit: the measurement point must lie in the solid beam "
                                       "(above the root; on the axis, below the groove)")

    @property
    def floor_height(self) -> float:
        """z of the cavity floor (m); the free end when there is no cavity."""
        return self.free_length - self.cavity_z

    @property
    def contact_below_top(self) -> float:
        """Depth of the sphere centre below the free end (m): the sphere rests on the groove's edges."""
        if self.cavity_z == 0:
            return 0.0
        return RigGeometry(cavity_z=self.cavity_z, groove_width=self.groove_width,
                           sphere_radius=self.sphere_radius).contact_below_top

    def wall_point(self, side: str, height: float | None = None) -> np.ndarray:
        """Centre of the left (x < 0) or right inner wall face at `height` (default: the contact height), m;
        without a cavity, of the section's outer x-faces."""
        half = 0.5 * (self.cavity_x if self.cavity_z > 0 else self.section_x)
        z = self.contact_height if height is None else height
        return np.array([-half if side == "left" else half, 0.0, z])

    @property
    def measurement_point(self) -> np.ndarray:
        """The measurement point (m): outer face x = +section_x/2 or axis, y = 0, measurement height."""
        return np.array([0.5 * self.section_x if self.measurement_on_face else 0.0, 0.0, self.measurement_height])

    def solid(self, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
        """True where the point (x, y, z) (m, arrays) lies inside the material (boundaries excluded: use
        centroids of grid boxes)."""
        ax, ay = np.abs(x), np.abs(y)
        block = (z < 0) & (z > -self.block_edge) & (ax < 0.5 * self.block_edge) & (ay < 0.5 * self.block_edge)
        beam = (z > 0) & (z < self.free_length) & (ax < 0.5 * self.section_x) & (ay < 0.5 * self.section_y)
        neck_cut = (z < self.neck_length) & ((ax > 0.5 * self.neck_width_x) | (ay > 0.5 * self.neck_width_y))
        cavity = (z > self.floor_height) & (ax < 0.5 * self.cavity_x) & (ay < 0.5 * self.cavity_y)
        groove = ((z > self.floor_height - self.groove_depth) & (z <= self.floor_height) & (ax < 0.5 * self.cavity_x)
                  & (ay < 0.5 * self.groove_width))
        return block | (beam & ~neck_cut & ~cavity & ~groove)

    def breakpoints(self) -> tuple[list[float], list[float], list[float]]:
        """Coordinates (m) that must be grid lines in x, y, z: every face, the contact and measurement heights,
        the mid-planes."""
        halves = lambda *widths: [s * 0.5 * w for w in widths if w > 0 for s in (-1, 1)]  # noqa: E731
        xs = halves(self.section_x, self.block_edge, self.neck_width_x if self.neck_length else 0,
                    self.cavity_x if self.cavity_z else 0) + [0.0]
        ys = halves(self.section_y, self.block_edge, self.neck_width_y if self.neck_length else 0,
                    self.cavity_y if self.cavity_z else 0, self.groove_width if self.groove_depth else 0) + [0.0]
        zs = [0.0, self.free_length, self.neck_length, self.floor_height, self.floor_height - self.groove_depth,
              self.contact_height, self.measurement_height, -self.block_edge]
        return xs, ys, zs

    def clamped(self, points: np.ndarray) -> np.ndarray:
        """True for the points (3, n), m, on the clamped faces: the block's lower face (and its side faces with
        clamp "block-faces"), or the beam's root section z = 0 without a block."""
        tol = 1e-9 * max(self.free_length, self.block_edge)
        if self.block_edge == 0:
            return np.abs(points[2]) < tol
        on = np.abs(points[2] + self.block_edge) < tol
        if self.clamp == "block-faces":
            half = 0.5 * self.block_edge
            side = (np.abs(np.abs(points[0]) - half) < tol) | (np.abs(np.abs(points[1]) - half) < tol)
            on |= (points[2] < tol) & side
        return on

    @property
    def beam_volume(self) -> float:
        """Volume of the beam above the block (m^3)."""
        neck = self.neck_length * (self.section_x * self.section_y - self.neck_width_x * self.neck_width_y) \
            if self.neck_length else 0.0
        cavity = self.cavity_x * self.cavity_y * self.cavity_z + self.cavity_x * self.groove_width * self.groove_depth
        return self.free_length * self.section_x * self.section_y - neck - cavity


@dataclass(frozen=True)
class SolidMaterial:
    """Isotropic linear-elastic steel (Table 1): E (Pa), nu (-), rho (kg/m^3)."""

    E: float = E_STEEL_PAPER
    nu: float = NU_STEEL
    rho: float = RHO_STEEL

    def __post_init__(self) -> None:
        if not (self.E > 0 and self.rho > 0 and -1 < self.nu < 0.5):
            raise SimulationInputError(f"material needs E > 0, rho > 0 and -1 < nu < 0.5, got E={self.E!r} Pa, "
                                       f"nu={self.nu!r}, rho={self.rho!r} kg/m^3")


def _unique_lines(points: Sequence[float]) -> np.ndarray:
    p = np.sort(np.asarray(points, float))
    keep = np.concatenate([[True], np.diff(p) > 1e-9])
    return p[keep]


def _subdivide(lines: np.ndarray, size: float) -> np.ndarray:
    """Split every interval between consecutive lines into ceil(length / size) equal parts."""
    out = [lines[:1]]
    for a, b in zip(lines[:-1], lines[1:]):
        n = max(1, math.ceil((b - a) / size - 1e-9))
        out.append(np.linspace(a, b, n + 1)[1:])
    return np.concatenate(out)


def _grid_axis(breaks: Sequence[float], beam: tuple[float, float], element_size: float) -> np.ndarray:
    """Grid lines along one axis: the breakpoints, intervals inside `beam` (lo, hi) split to element_size, those
    outside to a size growing by BLOCK_GROWTH per element away from the beam."""
    lines = _unique_lines(breaks)
    inner = _subdivide(lines[(lines >= beam[0] - 1e-12) & (lines <= beam[1] + 1e-12)], element_size)
    out = [lines, inner]
    for direction, edge in ((-1, lines[0]), (1, lines[-1])):
        start = inner[0] if direction < 0 else inner[-1]
        if abs(edge - start) < 1e-12:
            continue
        sizes, total = [], 0.0
        while total < abs(edge - start) - 1e-12:
            sizes.append(element_size * BLOCK_GROWTH ** (len(sizes) + 1))
            total += sizes[-1]
        steps = np.cumsum(sizes) * abs(edge - start) / total  # scaled to end on the edge
        out.append(start + direction * steps)
    return _unique_lines(np.concatenate(out))


@dataclass
class SolidMesh:
    """Assembled solid model: the scikit-fem mesh and vector basis (for point evaluation), the clamped stiffness
    K (N/m) and mass M (kg) over the free DOFs, the base inertia load M b (kg) for unit translations in x, y, z
    (columns), the free DOFs' global numbers and components (0 x, 1 y, 2 z), the total mass (kg) and the mirror
    maps of the free DOFs (index of the DOF at the point mirrored about x = 0 resp. y = 0, same component); quarter:
    only x >= 0, y >= 0 is meshed, with the x-bending mirror conditions (solid_mesh)."""

    geometry: SolidGeometry
    material: SolidMaterial
    element: str
    element_size: float
    mesh: object
    basis: object
    K: scipy.sparse.csc_matrix
    M: scipy.sparse.csc_matrix
    base_load: np.ndarray
    free: np.ndarray
    component: np.ndarray
    total_mass: float
    mirror_x: np.ndarray
    mirror_y: np.ndarray
    n_dofs: int
    quarter: bool = False

    @property
    def n_free(self) -> int:
        return int(self.free.size)

    def point_matrix(self, points: np.ndarray, component: int = 0) -> scipy.sparse.csr_matrix:
        """Rows that evaluate one displacement component at points (n, 3), m, from free-DOF vectors, by the
        elements' shape functions; a point on a face or edge takes any element that holds it."""
        return _point_matrix(self, np.atleast_2d(points), component)


@lru_cache(maxsize=4)
def _reference_matrices(element: str, material: SolidMaterial):
    """K_ij (3, 3, n, n) and M_1 (n, n) of the unit cube: K_e = sum_ij V / (h_i h_j) K_ij, M_e = V M_1 (read-only;
    cached: they cost about a second)."""
    skfem = _require_skfem()
    from skfem.helpers import dot

    lam = material.E * material.nu / ((1 + material.nu) * (1 - 2 * material.nu))
    mu = material.E / (2 * (1 + material.nu))
    delta = np.eye(3)
    C = (lam * np.einsum("ki,lj->kilj", delta, delta) + mu * np.einsum("kl,ij->kilj", delta, delta)
         + mu * np.einsum("kj,il->kilj", delta, delta))
    unit = skfem.MeshHex.init_tensor(np.array([0.0, 1.0]), np.array([0.0, 1.0]), np.array([0.0, 1.0]))
    basis = skfem.Basis(unit, _vector_element(element), intorder=5)
    dofs = basis.element_dofs[:, 0]
    K = np.zeros((3, 3, dofs.size, dofs.size))
    for i in range(3):
        for j in range(3):
            @skfem.BilinearForm
            def form(u, v, w, i=i, j=j):
                return sum(C[k, i, l, j] * u.grad[k, i] * v.grad[l, j] for k in range(3) for l in range(3)
                           if C[k, i, l, j] != 0)

            K[i, j] = skfem.asm(form, basis).toarray()[np.ix_(dofs, dofs)]

    @skfem.BilinearForm
    def mass(u, v, w):
        return material.rho * dot(u, v)

    M = skfem.asm(mass, basis).toarray()[np.ix_(dofs, dofs)]
    K.setflags(write=False)
    M.setflags(write=False)
    return K, M


def _vector_element(element: str):
    skfem = _require_skfem()
    if element not in ELEMENTS:
        raise SimulationInputError(f"unknown element {element!r}; choose one of {', '.join(ELEMENTS)}")
    return skfem.ElementVector(skfem.ElementHexS2() if element == "hex20" else skfem.ElementHex2())


def _dof_components(basis) -> np.ndarray:
    comp = np.empty(basis.N, dtype=np.int64)
    for kind in ("nodal_dofs", "edge_dofs", "facet_dofs", "interior_dofs"):
        rows = getattr(basis.dofs, kind)
        if rows is not None and rows.size:
            for r in range(rows.shape[0]):
                comp[rows[r]] = r % 3
    return comp


def _mirror(locs: np.ndarray, comp: np.ndarray, axis: int, scale: float) -> np.ndarray:
    """For every DOF the DOF of the same component at the location mirrored about the plane axis = 0."""
    from scipy.spatial import cKDTree

    key = np.column_stack([locs.T, comp * 10.0 * scale])
    mirrored = key.copy()
    mirrored[:, axis] *= -1
    dist, index = cKDTree(key).query(mirrored)
    if np.any(dist > 1e-9 * scale):
        return np.full(comp.size, -1)
    return index


def _stretch(lines: np.ndarray, breaks_from: Sequence[float], breaks_to: Sequence[float]) -> np.ndarray:
    """Map grid lines built for one set of breakpoints piecewise linearly onto another with the same count and
    order (so the element counts stay fixed and the model varies smoothly with the dimensions)."""
    a, b = _unique_lines(breaks_from), _unique_lines(breaks_to)
    if a.size != b.size:
        raise SimulationInputError("grid_from: the two geometries' faces do not correspond one to one (a feature "
                                   "appears, vanishes or changes order); mesh the geometry on its own grid")
    return np.interp(lines, a, b)


def solid_mesh(geometry: SolidGeometry = SolidGeometry(), material: SolidMaterial = SolidMaterial(),
               element_size: float = MESH_LEVELS["coarse"], element: str = "hex20", symmetry: str = "full",
               grid_from: SolidGeometry | None = None) -> SolidMesh:
    """Mesh and assemble the solid model (Sect. 3.1, Eq. 2: M, K of the clamped structure and M b).

    element_size: target element length along the beam (m); element: "hex20" (C3D20) or "hex27".
    symmetry "quarter" meshes x >= 0, y >= 0 only, with the x-bending mirror conditions (u_y = u_z = 0 on x = 0,
    u_y = 0 on y = 0): its modes are exactly the full model's modes of the x-bending class, at a quarter of the
    DOFs. K, M and M b are those of the full structure (the quarter's times 4), so mass normalisation, values and
    participation mean what they mean for the full model. grid_from: build the grid lines for this geometry and
    stretch them onto `geometry` (same element counts; for smooth derivatives in the updating).
    """
    skfem = _require_skfem()
    if not (isinstance(element_size, (int, float)) and 0 < element_size <= 0.016):
        raise SimulationInputError(f"element size must lie in (0, 16 mm] (the paper's wave-length rule, Sect. 3.1), "
                                   f"got {element_size!r} m")
    if symmetry not in SYMMETRIES:
        raise SimulationInputError(f"unknown symmetry {symmetry!r}; choose one of {', '.join(SYMMETRIES)}")
    g = geometry
    template = g if grid_from is None else grid_from
    bx, by, bz = template.breakpoints()
    x = _grid_axis(bx, (-0.5 * template.section_x, 0.5 * template.section_x), element_size)
    y = _grid_axis(by, (-0.5 * template.section_y, 0.5 * template.section_y), element_size)
    z = _grid_axis(bz, (0.0, template.free_length), element_size)
    if grid_from is not None:
        x, y, z = (_stretch(lines, a, b) for lines, a, b in zip((x, y, z), (bx, by, bz), g.breakpoints()))
    quarter = symmetry == "quarter"
    if quarter:
        x, y = x[x >= -1e-12], y[y >= -1e-12]
    full = skfem.MeshHex.init_tensor(x, y, z)
    centroids = full.p[:, full.t].mean(axis=1)
    mesh = full.restrict(np.flatnonzero(g.solid(*centroids)))
    basis = skfem.Basis(mesh, _vector_element(element), intorder=1)

    K_ref, M_ref = _reference_matrices(element, material)
    corners = mesh.p[:, mesh.t]
    h = corners.max(axis=1) - corners.min(axis=1)  # (3, n_el) box dimensions
    volume = h.prod(axis=0)
    n_loc = M_ref.shape[0]
    dofs = basis.element_dofs
    rows = np.broadcast_to(dofs[:, None, :], (n_loc, n_loc, dofs.shape[1])).ravel()
    cols = np.broadcast_to(dofs[None, :, :], (n_loc, n_loc, dofs.shape[1])).ravel()
    coef = volume[None, None] / (h[:, None] * h[None, :])  # (3, 3, n_el)
    k_el = np.einsum("ije,ijab->abe", coef, K_ref)
    m_el = np.einsum("e,ab->abe", volume, M_ref)
    shape = (basis.N, basis.N)
    K_full = scipy.sparse.csr_matrix((k_el.ravel(), (rows, cols)), shape=shape)
    del k_el
    M_full = scipy.sparse.csr_matrix((m_el.ravel(), (rows, cols)), shape=shape)
    del m_el, rows, cols

    comp = _dof_components(basis)
    locs = basis.doflocs
    fixed = g.clamped(locs)
    scale = max(g.free_length, g.block_edge)
    if quarter:
        on_x0, on_y0 = np.abs(locs[0]) < 1e-9 * scale, np.abs(locs[1]) < 1e-9 * scale
        fixed |= (on_x0 & (comp != 0)) | (on_y0 & (comp == 1))
        K_full, M_full = 4.0 * K_full, 4.0 * M_full
    free = np.flatnonzero(~fixed)
    unit = np.zeros((basis.N, 3))
    unit[np.arange(basis.N), comp] = 1.0
    load_full = M_full @ unit
    total_mass = float(unit[:, 0] @ load_full[:, 0])
    if quarter:
        load_full[:, 1:] = 0.0  # the x-bending class has no net y or z momentum
        mirrors = [np.full(free.size, -1)] * 2
    else:
        mirrors = []
        for axis in (0, 1):
            m = _mirror(locs[:, free], comp[free], axis, scale)
            mirrors.append(m if np.all(m >= 0) else np.full(free.size, -1))
    return SolidMesh(
        geometry=g, material=material, element=element, element_size=float(element_size), mesh=mesh, basis=basis,
        K=K_full[free][:, free].tocsc(), M=M_full[free][:, free].tocsc(), base_load=load_full[free],
        free=free, component=comp[free], total_mass=total_mass,
        mirror_x=mirrors[0], mirror_y=mirrors[1], n_dofs=int(basis.N), quarter=quarter)


# Parity of each displacement component of an x-bending mode under the mirrors x -> -x and y -> -y
X_BENDING_PARITY = np.array([[1.0, 1.0], [-1.0, -1.0], [-1.0, 1.0]])


def _point_matrix(solid: SolidMesh, points: np.ndarray, component: int) -> scipy.sparse.csr_matrix:
    if solid.quarter:  # a point outside the quarter takes the mirrored point's value, with the component's parity
        sign = np.prod(np.where(points[:, :2] < 0, X_BENDING_PARITY[component], 1.0), axis=1)
        mirrored = np.column_stack([np.abs(points[:, :2]), points[:, 2]])
        return scipy.sparse.diags(sign) @ _point_matrix(replace(solid, quarter=False), mirrored, component)
    mesh, basis = solid.mesh, solid.basis
    corners = mesh.p[:, mesh.t]
    lo, hi = corners.min(axis=1), corners.max(axis=1)
    tol = 1e-9 * max(solid.geometry.free_length, solid.geometry.block_edge)
    cells = []
    for p in points:
        inside = np.flatnonzero(np.all((lo <= p[:, None] + tol) & (hi >= p[:, None] - tol), axis=0))
        if inside.size == 0:
            raise SimulationInputError(f"point ({', '.join(f'{1e3 * c:.3f}' for c in p)}) mm lies outside the solid "
                                       "model; give a point on or inside the material")
        cells.append(inside[0])
    cells = np.array(cells)
    ref = basis.mapping.invF(points.T[:, :, None], tind=cells)
    n_fun = basis.Nbfun
    values = np.array([np.asarray(basis.elem.gbasis(basis.mapping, ref, k, tind=cells)[0])[component, :, 0]
                       for k in range(n_fun)])  # (n_fun, n_points)
    position = np.full(solid.n_dofs, -1)
    position[solid.free] = np.arange(solid.n_free)
    cols = position[basis.element_dofs[:, cells]]  # (n_fun, n_points)
    keep = (cols >= 0) & (values != 0)
    rows = np.broadcast_to(np.arange(points.shape[0])[None, :], cols.shape)
    return scipy.sparse.csr_matrix((values[keep], (rows[keep], cols[keep])), shape=(points.shape[0], solid.n_free))


# ---------------------------------------------------------------------------------------------------------
# Eigensolution and the x-bending modes

SYMMETRY_SHARE = 0.99  # a mode belongs to a symmetry class when this share of its kinetic energy does
X_DOMINANCE = 0.9  # x-bending: (phi^T M b_x)^2 at least this share of the three translations' sum
PARTICIPATION_FLOOR = 1e-6  # ... and at least this share of the largest (phi^T M b_x)^2 (excludes zero-mass modes)


def select_x_bending(participation: np.ndarray, symmetric: np.ndarray | None = None, n_modes: int = 9
                     ) -> tuple[np.ndarray, list[str]]:
    """The first n_modes x-bending modes of a spectrum (Sect. 3.1: the 9 lowest x-bending modes).

    participation: (n, 3) phi^T M b for unit translations in x, y, z (any consistent unit); symmetric: (n,) bool,
    True where the mode has the x-bending symmetry (symmetric about the plane y = 0, antisymmetric about x = 0),
    or None when unknown. A mode is x-bending when it has that symmetry and its x-participation dominates:
    p_x^2 >= X_DOMINANCE (p_x^2 + p_y^2 + p_z^2) and p_x^2 >= PARTICIPATION_FLOOR max(p_x^2) (torsion modes carry
    no translation at all). Returns the selected indices (ascending, at most n_modes) and one line per rejected
    mode below the last selected one, saying why.
    """
    p = np.asarray(participation, float)
    p2 = p**2
    floor = PARTICIPATION_FLOOR * max(float(p2[:, 0].max(initial=0.0)), np.finfo(float).tiny)
    selected, rejected = [], []
    for j in range(p2.shape[0]):
        if len(selected) == n_modes:
            break
        reasons = []
        if symmetric is not None and not symmetric[j]:
            reasons.append("not x-bending symmetric")
        if p2[j].max() < floor:
            reasons.append("no translational participation")
        elif p2[j, 0] < X_DOMINANCE * p2[j].sum():
            axis = 1 + int(np.argmax(p2[j, 1:]))
            reasons.append(f"{'xyz'[axis]}-participation {abs(p[j, axis]):.3g} against x {abs(p[j, 0]):.3g}")
        if reasons:
            rejected.append(f"mode {j + 1}: " + ", ".join(reasons))
        else:
            selected.append(j)
    return np.array(selected, dtype=int), rejected


def _symmetry_shares(solid: SolidMesh, phi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Shares of each mode's M-norm in the part symmetric about y = 0 and antisymmetric about x = 0 (NaN when the
    mesh is not mirror symmetric)."""
    if solid.quarter:  # the mirror conditions admit the x-bending class only
        return np.ones(phi.shape[1]), np.ones(phi.shape[1])
    if np.any(solid.mirror_x < 0) or np.any(solid.mirror_y < 0):
        return np.full(phi.shape[1], np.nan), np.full(phi.shape[1], np.nan)
    flip_y = np.where(solid.component == 1, -1.0, 1.0)[:, None]  # mirror about y = 0 reverses u_y
    flip_x = np.where(solid.component == 0, -1.0, 1.0)[:, None]
    norm = np.einsum("ij,ij->j", phi, solid.M @ phi)
    shares = []
    for mirrored, sign in ((flip_y * phi[solid.mirror_y], 1.0), (flip_x * phi[solid.mirror_x], -1.0)):
        part = 0.5 * (phi + sign * mirrored)
        shares.append(np.einsum("ij,ij->j", part, solid.M @ part) / norm)
    return shares[0], shares[1]


def _eigenpairs(solid: SolidMesh, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Lowest k eigenpairs of K phi = omega^2 M phi by shift-invert Lanczos about 0 (ARPACK through scipy; the
    symmetric factorisation of K by SuperLU with a minimum-degree ordering of K + K^T)."""
    lu = scipy.sparse.linalg.splu(solid.K, permc_spec="MMD_AT_PLUS_A", options={"SymmetricMode": True})
    op = scipy.sparse.linalg.LinearOperator(solid.K.shape, matvec=lu.solve, dtype=float)
    lam, phi = scipy.sparse.linalg.eigsh(solid.K, k=k, M=solid.M, sigma=0.0, which="LM", OPinv=op,
                                         v0=np.ones(solid.n_free))
    order = np.argsort(lam)
    return lam[order], phi[:, order]


@dataclass
class SolidModes:
    """The selected x-bending modes of a solid model (Sect. 3.1), ascending, mass-normalised (phi^T M phi = 1),
    each signed so that its mean wall value at the contact height is positive (sim/model/system.py).

    frequencies_hz (Hz); phi: (n_free, n) free-DOF vectors (1/sqrt(kg)); participation: (n, 3) phi^T M b for
    unit base translations in x, y, z (sqrt(kg)); kinetic_x_share: share of u_x in phi^T M phi (-);
    symmetric_y / antisymmetric_x: shares of the modes' M-norm with those symmetries (-); spectrum_hz: every
    computed frequency (Hz) and selected: the selected modes' indices in it; rejected: why the others were not
    taken; solve_time_s: assembly + eigensolution (s).
    """

    solid: SolidMesh
    frequencies_hz: np.ndarray
    phi: np.ndarray
    participation: np.ndarray
    kinetic_x_share: np.ndarray
    symmetric_y: np.ndarray
    antisymmetric_x: np.ndarray
    spectrum_hz: np.ndarray
    selected: np.ndarray
    rejected: list[str]
    solve_time_s: float = 0.0

    @property
    def n_modes(self) -> int:
        return int(self.frequencies_hz.size)

    def values_at(self, points: np.ndarray, component: int = 0) -> np.ndarray:
        """Displacement component (0 x, 1 y, 2 z) of every mode at points (n, 3), m: (n_points, n_modes), 1/sqrt(kg)."""
        return np.asarray(self.solid.point_matrix(np.atleast_2d(points), component) @ self.phi)

    def wall_values(self, height: float | None = None, patch_radius: float = 0.0,
                    points: tuple[Sequence[float], Sequence[float]] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """x-values (1/sqrt(kg)) of every mode at the left and right walls: at the centre of each inner wall face at
        `height` (m, default the sphere-centre height), or at the given (left, right) points (m); averaged over a
        circle of patch_radius (m) on the face (the plane x = const) when patch_radius > 0 (Sect. 3.1, Eqs. 5, 6)."""
        g = self.solid.geometry
        centres = [np.asarray(p, float) for p in points] if points is not None else \
            [g.wall_point("left", height), g.wall_point("right", height)]
        offsets, weights = _disc_rule(patch_radius)
        out = []
        for centre in centres:
            if centre.shape != (3,):
                raise SimulationInputError("a wall point needs three coordinates (x, y, z) in m")
            pts = centre[None, :] + np.column_stack([np.zeros(len(weights)), offsets])
            out.append(weights @ self.values_at(pts))
        return out[0], out[1]

    @property
    def tip_values(self) -> np.ndarray:
        """x-values at the measurement point (1/sqrt(kg))."""
        return self.values_at(self.solid.geometry.measurement_point)[0]


def _disc_rule(radius: float) -> tuple[np.ndarray, np.ndarray]:
    """Points (n, 2) (offsets in y, z; m) and weights (sum 1) averaging over a disc: Gauss-Legendre in r^2 (4 rings)
    times 12 equal angles, exact for polynomials of degree 7 in y, z; the centre alone for radius 0."""
    if not (isinstance(radius, (int, float)) and math.isfinite(radius) and radius >= 0):
        raise SimulationInputError(f"patch radius must be a non-negative length in m, got {radius!r}")
    if radius == 0:
        return np.zeros((1, 2)), np.ones(1)
    s, w = np.polynomial.legendre.leggauss(4)
    r = radius * np.sqrt(0.5 * (s + 1.0))
    angle = 2.0 * np.pi * np.arange(12) / 12
    offsets = np.column_stack([(r[:, None] * np.cos(angle)).ravel(), (r[:, None] * np.sin(angle)).ravel()])
    weights = np.repeat(0.5 * w / 12.0, angle.size)
    return offsets, weights


def solve_solid_modes(solid: SolidMesh, n_modes: int = 9) -> SolidModes:
    """The n_modes lowest x-bending modes of an assembled solid model (Sect. 3.1, Eqs. 2, 7): shift-invert
    eigensolution, selection by symmetry and x-participation (select_x_bending), mass normalisation, signs."""
    if isinstance(n_modes, bool) or int(n_modes) != n_modes or not 1 <= n_modes <= 40:
        raise SimulationInputError(f"n_modes must be an integer between 1 and 40, got {n_modes!r}")
    start = time.perf_counter()
    k = n_modes + 4 if solid.quarter else 4 * n_modes
    while True:
        k = min(k, solid.n_free - 2)
        lam, phi = _eigenpairs(solid, k)
        phi = phi / np.sqrt(np.einsum("ij,ij->j", phi, solid.M @ phi))
        participation = phi.T @ solid.base_load
        sym_y, anti_x = _symmetry_shares(solid, phi)
        symmetric = None if np.isnan(sym_y).any() else (sym_y >= SYMMETRY_SHARE) & (anti_x >= SYMMETRY_SHARE)
        chosen, rejected = select_x_bending(participation, symmetric, n_modes)
        if chosen.size == n_modes or k >= solid.n_free - 2 or k >= 400:
            break
        k *= 2
    if chosen.size < n_modes:
        raise SimulationInputError(f"only {chosen.size} x-bending modes among the {k} lowest modes of the solid model; "
                                   "check the geometry")
    phi = phi[:, chosen]
    modes = SolidModes(solid=solid, frequencies_hz=np.sqrt(lam[chosen]) / (2 * np.pi), phi=phi,
                       participation=participation[chosen], kinetic_x_share=np.zeros(n_modes),
                       symmetric_y=sym_y[chosen], antisymmetric_x=anti_x[chosen],
                       spectrum_hz=np.sqrt(np.maximum(lam, 0.0)) / (2 * np.pi), selected=chosen, rejected=rejected)
    left, right = modes.wall_values()
    sign = np.where(left + right < 0, -1.0, 1.0)
    modes.phi = phi * sign
    modes.participation = modes.participation * sign[:, None]
    ux = modes.phi * (solid.component == 0)[:, None]
    modes.kinetic_x_share = np.einsum("ij,ij->j", ux, solid.M @ ux)
    modes.solve_time_s = time.perf_counter() - start
    return modes


# ---------------------------------------------------------------------------------------------------------
# The modal model of the rig, with provenance and mesh convergence


def solid_modal_model(modes: SolidModes, patch_radius: float = 0.0,
                      wall_points: tuple[Sequence[float], Sequence[float]] | None = None) -> ModalModel:
    """The modal model of Eq. 7 from solid modes: frequencies, damping (sim.hosts.rig.damping_ratios), wall values (see
    SolidModes.wall_values), tip values and x-participation, each mode signed so its mean wall value is positive;
    the beam mass of Eq. 10 (density times the free length's volume) and the floor values of Appendix C (x-values
    at the two groove edges the sphere rests on, averaged; without a groove the floor's centre)."""
    left, right = modes.wall_values(patch_radius=patch_radius, points=wall_points)
    sign = np.where(left + right < 0, -1.0, 1.0)
    s = modes.solid
    g = s.geometry
    half = 0.5 * g.groove_width if g.groove_depth > 0 else 0.0
    floor = modes.values_at(np.array([[0.0, -half, g.floor_height], [0.0, half, g.floor_height]])).mean(axis=0)
    return ModalModel(
        frequencies_hz=modes.frequencies_hz, damping_ratios=damping_ratios(modes.n_modes),
        phi_wall_left=sign * left, phi_wall_right=sign * right, phi_tip=sign * modes.tip_values,
        participation=sign * modes.participation[:, 0], beam_mass=s.material.rho * g.beam_volume,
        phi_floor=sign * floor, **rig_host(),
        source=f"3D solid model (sim.hosts.solid, {s.element}, element size {1e3 * s.element_size:g} mm, "
               f"{s.n_free} free DOFs, E = {s.material.E / 1e9:g} GPa)")


@dataclass(frozen=True)
class SolidResult:
    """What `ies modes --solid` shows and saves: the modal model, the modes on this mesh and on the coarser
    convergence partner (None when not computed), provenance (plain data for the modal file's [provenance] table)
    and the report lines to print."""

    model: ModalModel
    modes: SolidModes
    coarser_model: ModalModel | None
    provenance: dict
    report: list[str]


def modulus_for_frequencies(frequencies_hz: np.ndarray, E: float, targets_hz: Sequence[float]) -> np.ndarray:
    """The modulus (Pa) that would move each frequency onto its target: f ~ sqrt(E) at fixed geometry and density."""
    f = np.asarray(frequencies_hz, float)[: len(targets_hz)]
    return E * (np.asarray(targets_hz, float)[: f.size] / f) ** 2


def _convergence(model: ModalModel, coarser: ModalModel, size: float, coarse_size: float) -> dict:
    table = {"element_size_m": [coarse_size, size]}
    changes = {}
    for key in ("frequencies_hz", "phi_wall_left", "phi_wall_right", "phi_tip", "participation"):
        fine, coarse = getattr(model, key), getattr(coarser, key)
        table[key] = [coarse.tolist(), fine.tolist()]
        changes[key] = (fine / coarse - 1.0).tolist()
    table["relative_change"] = changes
    return table


def solid_rig_model(mesh: str | float = "coarse", geometry: SolidGeometry = SolidGeometry(),
                    material: SolidMaterial = SolidMaterial(), *, element: str = "hex20", n_modes: int = 9,
                    patch_radius: float = 0.0, wall_points: tuple[Sequence[float], Sequence[float]] | None = None,
                    convergence: bool = True, symmetry: str = "full") -> SolidResult:
    """The rig's modal model from the 3D solid model (Sect. 3.1, Eq. 7; `ies modes --solid`): mesh level "coarse",
    "medium" or "fine" (MESH_LEVELS) or an element size in m; with convergence, the same model on a mesh
    CONVERGENCE_RATIO times coarser too, for the provenance's convergence table. Coarse: about 1 min, 1 GB;
    symmetry "quarter" (solid_mesh): the same modes in about 10 s."""
    if isinstance(mesh, str):
        if mesh not in MESH_LEVELS:
            raise SimulationInputError(f"unknown mesh level {mesh!r}; choose one of {', '.join(MESH_LEVELS)}")
        size = MESH_LEVELS[mesh]
    else:
        size = float(mesh)
    solid = solid_mesh(geometry, material, size, element, symmetry)
    modes = solve_solid_modes(solid, n_modes)
    model = solid_modal_model(modes, patch_radius, wall_points)
    coarser = None
    if convergence:
        partner = solve_solid_modes(solid_mesh(geometry, material, size * CONVERGENCE_RATIO, element, symmetry),
                                    n_modes)
        coarser = solid_modal_model(partner, patch_radius, wall_points)
    g = geometry
    left, right = (wall_points if wall_points is not None else (g.wall_point("left"), g.wall_point("right")))
    from sim.hosts.rig import F_MEASURED_HZ, F9_PAPER_HZ

    E_wanted = modulus_for_frequencies(model.frequencies_hz, material.E, F_MEASURED_HZ)
    E_f9 = modulus_for_frequencies(model.frequencies_hz[8:9], material.E, [F9_PAPER_HZ]) if n_modes >= 9 else []
    provenance = {
        "model": "3D solid finite elements (sim.hosts.solid)",
        "element": ELEMENT_NAMES[element],
        "mesh_level": mesh if isinstance(mesh, str) else "custom", "element_size_m": size,
        "elements": int(solid.mesh.t.shape[1]), "free_dofs": solid.n_free, "solve_time_s": modes.solve_time_s,
        "symmetry": symmetry,
        "clamp": g.clamp if g.block_edge > 0 else "root section", "geometry": asdict(g),
        "material": asdict(material), "total_mass_kg": solid.total_mass,
        "beam_mass_kg": material.rho * g.beam_volume,
        "wall_left_m": np.asarray(left, float), "wall_right_m": np.asarray(right, float),
        "patch_radius_m": patch_radius, "tip_m": g.measurement_point,
        "selected_modes": modes.selected + 1, "rejected_modes": modes.rejected,
        "kinetic_x_share": modes.kinetic_x_share,
        "E_for_measured_f1_f4_Pa": E_wanted, "E_for_paper_f9_Pa": E_f9,
    }
    if coarser is not None:
        provenance["convergence"] = _convergence(model, coarser, size, size * CONVERGENCE_RATIO)
    report = [
        f"solid model: {provenance['element']}, element size {1e3 * size:g} mm, {provenance['elements']} elements, "
        f"{solid.n_free} free DOFs, clamp {provenance['clamp']}, E = {material.E / 1e9:g} GPa; "
        f"assembly + modes {modes.solve_time_s:.0f} s",
        f"beam mass {provenance['beam_mass_kg']:.3f} kg (free length), with the block {solid.total_mass:.3f} kg; "
        f"{len(modes.rejected)} other modes below the last x-bending mode (listed in the provenance)",
        "E the measured f1..f4 would want (Table A.1): " + ", ".join(f"{e / 1e9:.1f}" for e in E_wanted) + " GPa"
        + (f"; the paper's f9 = 19.8 kHz: {E_f9[0] / 1e9:.1f} GPa" if len(E_f9) else ""),
    ]
    if coarser is not None:
        ch = provenance["convergence"]["relative_change"]
        worst = lambda key: 100 * max(abs(v) for v in ch[key])  # noqa: E731
        walls = max(worst("phi_wall_left"), worst("phi_wall_right"))
        report.append(f"mesh convergence against {1e3 * size * CONVERGENCE_RATIO:g} mm: max change "
                      f"f {worst('frequencies_hz'):.2f} %, walls {walls:.2f} %, tip {worst('phi_tip'):.2f} %, "
                      f"participation {worst('participation'):.2f} %")
    return SolidResult(model, modes, coarser, to_jsonable(provenance), report)


# ---------------------------------------------------------------------------------------------------------
# The same rig as a Timoshenko beam (sim.hosts.rig), like for like


def timoshenko_counterpart(geometry: SolidGeometry, material: SolidMaterial = SolidMaterial(),
                           n_modes: int = 9):
    """The Timoshenko beam model (sim.hosts.rig, module docstring: Cowper shear coefficients, the cavity and groove as
    tube sections, cubic elements) of the same rig as a solid model clamped at its root section (block_edge = 0):
    the same free length, neck, section, cavity and groove (m), the same E (Pa), nu and rho (kg/m^3), a rigid
    joint (the solid's clamped root face). The beam's contact and measurement points lie at the same heights, on
    the axis (the solid reads the inner wall faces and, with measurement_on_face, the outer face). A solid
    without a neck gets a neck of the full section (the same beam). Returns sim.hosts.rig.RigModes (frequencies Hz,
    values 1/sqrt(kg), participation sqrt(kg))."""
    from sim.hosts.rig import RigParameters, rig_modes

    g = geometry
    if g.block_edge != 0 or g.cavity_z == 0 or g.groove_depth == 0:
        raise SimulationInputError("timoshenko_counterpart needs a solid clamped at its root section (block_edge = 0) "
                                   "with a cavity and a groove, as the beam model has")
    neck = (g.neck_length, g.neck_width_x, g.neck_width_y) if g.neck_length > 0 else (1e-3, g.section_x, g.section_y)
    params = RigParameters(E=material.E, neck_length=neck[0], neck_width_x=neck[1], neck_width_y=neck[2])
    rig = RigGeometry(free_length=g.free_length, section_x=g.section_x, section_y=g.section_y, cavity_x=g.cavity_x,
                      cavity_y=g.cavity_y, cavity_z=g.cavity_z, groove_depth=g.groove_depth,
                      groove_width=g.groove_width, sphere_radius=g.sphere_radius,
                      measurement_below_contact=g.measurement_below_contact, block_edge=0.0)
    return rig_modes(params, rig, n_modes=n_modes, nu=material.nu, rho=material.rho)


def compare_with_timoshenko(geometry: SolidGeometry, material: SolidMaterial = SolidMaterial(),
                            mesh: str | float = "coarse", n_modes: int = 9) -> dict:
    """The solid model (quarter symmetry) of a rig clamped at its root section against its Timoshenko counterpart
    (timoshenko_counterpart): per mode the frequencies (Hz), the values at the contact point (solid: mean of the two
    wall-face centres at the sphere-centre height; beam: the axis at that height), at the measurement point and the
    participation (1/sqrt(kg), sqrt(kg)) of both, and the ratios solid / beam (frequency ratios minus 1).
    Plain data (lists per mode)."""
    size = MESH_LEVELS[mesh] if isinstance(mesh, str) and mesh in MESH_LEVELS else mesh
    if isinstance(size, str):
        raise SimulationInputError(f"unknown mesh level {mesh!r}; choose one of {', '.join(MESH_LEVELS)}")
    beam = timoshenko_counterpart(geometry, material, n_modes)
    model = solid_modal_model(solve_solid_modes(solid_mesh(geometry, material, size, symmetry="quarter"), n_modes))
    solid = {"frequencies_hz": model.frequencies_hz, "phi_c": 0.5 * (model.phi_wall_left + model.phi_wall_right),
             "phi_tip": model.phi_tip, "participation": model.participation}
    timo = {"frequencies_hz": beam.frequencies_hz, "phi_c": beam.phi_contact, "phi_tip": beam.phi_tip,
            "participation": beam.participation}
    out = {"element_size_m": float(size), "solid": solid, "beam": timo,
           "f_rel_diff": solid["frequencies_hz"] / timo["frequencies_hz"] - 1.0}
    out.update({f"{key}_ratio": solid[key] / timo[key] for key in ("phi_c", "phi_tip", "participation")})
    return to_jsonable(out)


# ---------------------------------------------------------------------------------------------------------
# Model updating of the unpublished geometry (Appendix A)

# Bounds (m) of the dimensions the updating may move: the neck (not published) and the free length ("about 400 mm")
UPDATING_BOUNDS = {
    "neck_length": (0.005, 0.2),
    "neck_width_x": (0.008, _RIG.section_x),
    "neck_width_y": (0.004, _RIG.section_y),
    "free_length": (0.38, 0.42),
}
# Weights of the relative errors of f1..f4 (Table A.1) and f9 (the paper's 19.8 kHz) in the updating: f1 as
# closely as the paper's model has it (0.05 %), f9 only as a weak target (the paper rounds it).
UPDATING_WEIGHTS = (10.0, 1.0, 1.0, 1.0, 0.3)

# Results of update_solid_geometry (coarse mesh, E = 207 GPa, clamp "block-faces", neck cut in y from the block's
# top face; uq/studies/README.md, the solid against the beam). Both optima are unique: other starts end on the same dimensions.
# Neck length and y-width free, free length 400 mm: f1..f4 +0.01, -4.00, -2.72, -4.13 % (Table A.1), f9 = 19.69 kHz
# (-0.6 %), beam 1.600 kg, m_a phi_c1^2 = 3.53 %, phi_tip/phi_c = 0.960. The neck cut in x as well does not help
# (its x-width goes to the section's 28 mm), nor a rigid root instead of the block (-2.26, -0.47, -1.51 %, f9
# +1.9 %); the lower face alone as clamp lets the block rock at 4.3-4.8 kHz (two modes where Fig. A.1 has one).
NECK_UPDATED_GEOMETRY = SolidGeometry(neck_length=0.15650454, neck_width_y=0.013464524)
# The free length ("about 400 mm", Sect. 2) free as well: 391.8 mm, neck 143.3 x 12.19 mm (y): f1..f4 +0.004,
# -1.36, +0.63, +0.12 % (the paper's model: 0.05, 1.4, 0.5, 0.7 %), f9 = 20.41 kHz (+3.1 %), beam 1.545 kg (the
# paper: ca. 1.8 kg), m_a phi_c1^2 = 3.57 % (3.6 %), phi_tip/phi_c = 0.959 (0.96). Medium mesh: f1..f9 0.10-0.16 %
# lower, the wall values within 0.06 %; fine: f a further 0.05-0.06 % lower, the wall values of modes 1-6 within
# 0.25 %, modes 7-9 0.4-0.9 % higher. The wall values at the contact differ from the beam model's by +0.1..+5 %.
UPDATED_SOLID_GEOMETRY = SolidGeometry(free_length=0.39182730, neck_length=0.14333625, neck_width_y=0.012186451)


@dataclass(frozen=True)
class SolidUpdate:
    """Result of update_solid_geometry: the updated geometry; the nine x-bending frequencies (Hz); the relative
    errors of f1..f4 against Table A.1 and of f9 against the paper's 19.8 kHz (-); the weighted residuals and the
    cost 1/2 sum r^2; the beam mass (kg, free length) and the modal quantities m_a phi_c1^2 and phi_tip/phi_c of
    mode 1 (Sect. 2: 3.6 %, 0.96); the free dimensions on a bound; the number of eigen-solutions."""

    geometry: SolidGeometry
    frequencies_hz: np.ndarray
    frequency_errors: np.ndarray
    f9_error: float
    residuals: np.ndarray
    cost: float
    beam_mass: float
    modal_mass_ratio: float
    phi_tip_over_phi_c: float
    on_bounds: tuple[str, ...]
    n_solves: int


def update_solid_geometry(free: Sequence[str] = ("neck_length", "neck_width_y"), start: SolidGeometry = SolidGeometry(),
                          material: SolidMaterial = SolidMaterial(), mesh: str | float = "coarse",
                          weights: Sequence[float] = UPDATING_WEIGHTS, bounds: dict | None = None,
                          targets_hz: Sequence[float] | None = None) -> SolidUpdate:
    """Model updating like Appendix A, with E fixed (Table 1, 207 GPa) and the unpublished dimensions free: bounded
    weighted least squares (scipy trust-region reflective, forward differences) of w_j (f_j / f_target_j - 1)
    over the `free` fields of SolidGeometry (UPDATING_BOUNDS, or `bounds` {name: (lo, hi)} in m), targets f1..f4 of
    Table A.1 and the paper's f9 = 19.8 kHz (or `targets_hz`: five values, Hz; weights UPDATING_WEIGHTS). Each evaluation solves the quarter model
    on a grid stretched from the start geometry (fixed element counts: smooth in the dimensions); a second pass
    re-grids at the first pass's optimum. The clamp and the other fields stay as in `start`. Coarse mesh: about
    7 s per solve, 2-10 min in all."""
    from scipy.optimize import least_squares

    from sim.hosts.rig import F9_PAPER_HZ, F_MEASURED_HZ
    from sim.model.system import SPHERE_MASS

    size = MESH_LEVELS[mesh] if isinstance(mesh, str) and mesh in MESH_LEVELS else mesh
    if isinstance(size, str):
        raise SimulationInputError(f"unknown mesh level {mesh!r}; choose one of {', '.join(MESH_LEVELS)}")
    limits = dict(UPDATING_BOUNDS, **(bounds or {}))
    unknown = [name for name in free if name not in limits]
    if not free or unknown:
        raise SimulationInputError(f"update_solid_geometry: free dimensions must be among {', '.join(limits)}, "
                                   f"got {', '.join(unknown) or 'none'}")
    lo, hi = (np.array([limits[name][k] for name in free], float) for k in (0, 1))
    targets = np.array(F_MEASURED_HZ + (F9_PAPER_HZ,) if targets_hz is None else targets_hz, float)
    w = np.asarray(weights, float)
    if targets.shape != (5,) or w.shape != (5,) or np.any(w < 0) or np.any(targets <= 0):
        raise SimulationInputError("update_solid_geometry: give five positive targets (f1..f4, f9; Hz) and five "
                                   "non-negative weights")
    geometry_of = lambda u: replace(start, **{n: float(v) for n, v in zip(free, lo + u * (hi - lo))})  # noqa: E731
    solves = {}

    def solve(u: np.ndarray, grid: SolidGeometry) -> SolidModes:
        key = (tuple(np.round(u, 12)), id(grid))
        if key not in solves:
            geometry = geometry_of(u)
            try:
                solid = solid_mesh(geometry, material, size, symmetry="quarter", grid_from=grid)
            except SimulationInputError:  # two faces meet (e.g. the neck's and the groove's): the geometry's own grid
                solid = solid_mesh(geometry, material, size, symmetry="quarter")
            solves[key] = solve_solid_modes(solid, 9)
        return solves[key]

    u = np.clip((np.array([getattr(start, n) for n in free]) - lo) / (hi - lo), 0.0, 1.0)
    grid = start
    for _ in range(2):
        residuals = lambda v, grid=grid: w * (solve(v, grid).frequencies_hz[[0, 1, 2, 3, 8]] / targets - 1.0)  # noqa: E731
        fit = least_squares(residuals, u, bounds=(0.0, 1.0), diff_step=1e-3, xtol=1e-6, ftol=1e-10, gtol=1e-10,
                            max_nfev=60)
        u, grid = fit.x, geometry_of(fit.x)
    geometry = geometry_of(u)
    modes = solve(u, grid)
    f = modes.frequencies_hz
    r = w * (f[[0, 1, 2, 3, 8]] / targets - 1.0)
    phi_c = float(np.mean(modes.wall_values(), axis=0)[0])
    return SolidUpdate(
        geometry=geometry, frequencies_hz=f, frequency_errors=f[:4] / targets[:4] - 1.0,
        f9_error=float(f[8] / targets[4] - 1.0), residuals=r, cost=0.5 * float(r @ r),
        beam_mass=material.rho * geometry.beam_volume, modal_mass_ratio=SPHERE_MASS * phi_c**2,
        phi_tip_over_phi_c=float(modes.tip_values[0]) / phi_c,
        on_bounds=tuple(n for n, v in zip(free, u) if min(v, 1.0 - v) < 1e-4), n_solves=len(solves))
