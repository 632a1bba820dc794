"""Influence coefficients of an elastic half-space for uniform tractions on square surface elements.

Seed paper, Sect. 4.1: "the elements of the corresponding coefficient matrix can be expressed in
closed form". The surface is a regular grid of square elements of side dx; tractions are uniform on
each element and displacements are collocated at element centres. Array axis 0 is x, axis 1 is y.

Normal (Boussinesq, Love 1929): a pressure p on the element centred at the origin displaces the
point (x, y) by u_z = p / (pi E*) * [A + B], with the corner sums of A(x, y) = x asinh(y/|x|)
(the antiderivative of y^2/r^3) and B(x, y) = y asinh(x/|y|) (of x^2/r^3); A + B integrates 1/r.
Johnson, Contact Mechanics (1985), Eq. 3.25.

Tangential (Cerruti): a point force Q_x on one body displaces its surface by
u_x = Q_x/(2 pi G) [(1 - nu)/r + nu x^2/r^3], u_y = Q_x/(2 pi G) nu x y/r^3 (Johnson, Eq. 3.86);
x y / r^3 integrates to C(x, y) = -r. Two bodies add their compliances (E* for normal, the pair
of materials for tangential); the normal-tangential coupling through Dundurs' beta is neglected,
as in Mindlin's solution.

Two ways to apply an operator share one kernel table: an explicit dense matrix (small grids) and a
zero-padded FFT convolution (any grid, non-periodic); they agree to round-off.
"""
from __future__ import annotations

import numpy as np

from bem_contact.errors import ContactInputError
from bem_contact.materials import Material

# Dense matrices above this many bytes are refused (the FFT operator handles any grid).
DENSE_MEMORY_LIMIT = 2 * 1024**3


def _asinh_term(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """x asinh(y/|x|), continued by 0 on x = 0."""
    ax = np.abs(x)
    with np.errstate(divide="ignore", invalid="ignore"):
        value = x * np.arcsinh(y / ax)
    return np.where(ax > 0, value, 0.0)


def _corner_sum(antiderivative, X: np.ndarray, Y: np.ndarray, half: float) -> np.ndarray:
    """Integral over the square [X-half, X+half] x [Y-half, Y+half] from a mixed antiderivative."""
    return (
        antiderivative(X + half, Y + half)
        - antiderivative(X - half, Y + half)
        - antiderivative(X + half, Y - half)
        + antiderivative(X - half, Y - half)
    )


def _offsets(n: int, m: int, dx: float) -> tuple[np.ndarray, np.ndarray]:
    """Centre-to-centre offsets (m) of an n x m grid, shape (2n-1, 2m-1), zero offset at [n-1, m-1]."""
    if n < 1 or m < 1:
        raise ContactInputError(f"grid {n}x{m} is empty; use at least 1x1 elements")
    if not (np.isfinite(dx) and dx > 0):
        raise ContactInputError(f"grid pitch dx = {dx!r} m must be a finite number > 0")
    ix = np.arange(-(n - 1), n) * dx
    iy = np.arange(-(m - 1), m) * dx
    return np.meshgrid(ix, iy, indexing="ij")


def love_integrals(X: np.ndarray, Y: np.ndarray, dx: float) -> tuple[np.ndarray, np.ndarray]:
    """Integrals of y^2/r^3 (A) and x^2/r^3 (B) over the square element of side dx centred at the origin,
    seen from the points (X, Y) (m); A + B is the integral of 1/r (in m)."""
    half = 0.5 * dx
    A = _corner_sum(_asinh_term, X, Y, half)
    B = _corner_sum(lambda x, y: _asinh_term(y, x), X, Y, half)
    return A, B


def love_kernel(n: int, m: int, dx: float, E_star: float) -> np.ndarray:
    """Normal compliance table (m/Pa) of an n x m grid: u_z at offset (i, j) per unit pressure, Love's solution."""
    _check_modulus(E_star, "contact modulus E*")
    X, Y = _offsets(n, m, dx)
    A, B = love_integrals(X, Y, dx)
    return (A + B) / (np.pi * E_star)


def cerruti_kernels(n: int, m: int, dx: float, a: Material, b: Material) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Tangential compliance tables (m/Pa) K_xx, K_yy, K_xy of an n x m grid for two bodies (Cerruti)."""
    X, Y = _offsets(n, m, dx)
    A, B = love_integrals(X, Y, dx)
    C = _corner_sum(lambda x, y: -np.hypot(x, y), X, Y, 0.5 * dx)
    alpha = sum((1.0 - mat.nu) / (2.0 * np.pi * mat.G) for mat in (a, b))
    beta = sum(1.0 / (2.0 * np.pi * mat.G) for mat in (a, b))
    gamma = beta - alpha  # sum of nu / (2 pi G)
    return alpha * A + beta * B, beta * A + alpha * B, gamma * C


def _check_modulus(value: float, what: str) -> None:
    if not (np.isfinite(value) and value > 0):
        raise ContactInputError(f"{what} = {value!r} Pa must be a finite number > 0 (steel on brass: 75.09e9)")


class ConvolutionOperator:
    """Linear map u = K p on an n x m grid whose coefficients depend only on the offset (a Toeplitz block).

    Built from a kernel table of shape (2n-1, 2m-1) (zero offset at [n-1, m-1]). ``op(p)`` applies it
    by a zero-padded FFT (non-periodic, O(N log N)); ``op.dense()`` returns the explicit matrix.
    """

    def __init__(self, table: np.ndarray, workers: int = 1) -> None:
        table = np.asarray(table, dtype=float)
        if table.ndim != 2 or table.shape[0] % 2 == 0 or table.shape[1] % 2 == 0:
            raise ValueError("kernel table must have odd shape (2n-1, 2m-1)")
        self.table = table
        self.shape = ((table.shape[0] + 1) // 2, (table.shape[1] + 1) // 2)
        self.workers = workers
        self._kernel_hat: np.ndarray | None = None
        self._fft_shape: tuple[int, int] | None = None

    @property
    def self_compliance(self) -> float:
        """Displacement of an element under its own unit traction (the matrix diagonal)."""
        n, m = self.shape
        return float(self.table[n - 1, m - 1])

    def restricted(self, n: int, m: int) -> "ConvolutionOperator":
        """The same operator on an n x m sub-grid (a window of the original grid)."""
        N, M = self.shape
        if not (1 <= n <= N and 1 <= m <= M):
            raise ValueError(f"sub-grid {n}x{m} does not fit into {N}x{M}")
        return ConvolutionOperator(self.table[N - n : N + n - 1, M - m : M + m - 1], self.workers)

    def _prepare(self) -> None:
        import scipy.fft  # imported on first use (keeps `ies --help` fast)

        n, m = self.shape
        s = (scipy.fft.next_fast_len(2 * n - 1, real=True), scipy.fft.next_fast_len(2 * m - 1, real=True))
        wrapped = np.zeros(s)
        # offset i goes to index i mod s: the circular convolution equals the linear one on the grid
        rows = np.r_[0:n, s[0] - n + 1 : s[0]]
        cols = np.r_[0:m, s[1] - m + 1 : s[1]]
        shifted = np.roll(np.roll(self.table, -(n - 1), axis=0), -(m - 1), axis=1)
        wrapped[np.ix_(rows, cols)] = shifted
        self._fft_shape = s
        self._kernel_hat = scipy.fft.rfft2(wrapped, workers=self.workers)

    def __call__(self, p: np.ndarray) -> np.ndarray:
        """Apply the operator to a traction field p of shape (n, m); returns the displacement field."""
        import scipy.fft

        if self._kernel_hat is None:
            self._prepare()
        n, m = self.shape
        N0, N1 = self._fft_shape
        # pruned 2-D transform: the zero rows of the padded input and the unused output rows are skipped
        spectrum = scipy.fft.rfft(p, n=N1, axis=1, workers=self.workers)
        spectrum = scipy.fft.fft(spectrum, n=N0, axis=0, workers=self.workers, overwrite_x=True)
        spectrum *= self._kernel_hat
        spectrum = scipy.fft.ifft(spectrum, axis=0, workers=self.workers, overwrite_x=True)[:n]
        return scipy.fft.irfft(spectrum, n=N1, axis=1, workers=self.workers)[:, :m]

    def dense(self) -> np.ndarray:
        """Explicit (n m) x (n m) matrix in C order of the grid; refused when it would not fit in memory."""
        n, m = self.shape
        size = n * m
        if 8 * size * size > DENSE_MEMORY_LIMIT:
            raise ContactInputError(
                f"a dense influence matrix for a {n}x{m} grid needs {8 * size * size / 1024**3:.1f} GiB; "
                "use the FFT operator (solver 'pk'), which handles any grid"
            )
        i, j = np.divmod(np.arange(size), m)
        rows = i[:, None] - i[None, :] + n - 1
        cols = j[:, None] - j[None, :] + m - 1
        return self.table[rows, cols]


def normal_operator(shape: tuple[int, int], dx: float, E_star: float, workers: int = 1) -> ConvolutionOperator:
    """Normal influence operator (Love/Boussinesq) of a grid: pressure (Pa) -> normal displacement (m)."""
    return ConvolutionOperator(love_kernel(shape[0], shape[1], dx, E_star), workers)


class TangentialOperator:
    """Cerruti operator of a grid: tractions (q_x, q_y) in Pa -> relative slip displacements (u_x, u_y) in m."""

    def __init__(self, shape: tuple[int, int], dx: float, a: Material, b: Material, workers: int = 1) -> None:
        kxx, kyy, kxy = cerruti_kernels(shape[0], shape[1], dx, a, b)
        self.shape = tuple(shape)
        self.xx = ConvolutionOperator(kxx, workers)
        self.yy = ConvolutionOperator(kyy, workers)
        self.xy = ConvolutionOperator(kxy, workers)

    def __call__(self, qx: np.ndarray, qy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Slip displacements (u_x, u_y) for tractions (q_x, q_y)."""
        return self.xx(qx) + self.xy(qy), self.xy(qx) + self.yy(qy)

    def dense(self) -> np.ndarray:
        """Explicit 2N x 2N matrix acting on [q_x, q_y] stacked (each in C order)."""
        xy = self.xy.dense()
        return np.block([[self.xx.dense(), xy], [xy, self.yy.dense()]])
