"""Rotation algebra for planar angles and spatial Euler parameters, vectorised over leading axes.

Conventions
-----------
Planar body orientation is the angle θ; its rotation matrix is ``A(θ) = [[c, -s], [s, c]]``.

Spatial body orientation is a unit quaternion of Euler parameters ``p = (e0, e1, e2, e3)``
(scalar first).  With ``e = (e1, e2, e3)`` the rotation matrix from body to global frame is
(Nikravesh 1988, Eq. 6.19)::

    A(p) = (2 e0² − 1) I + 2 (e eᵀ + e0 ẽ)

where ``ẽ`` is the skew-symmetric matrix of ``e``.  The angular velocity used as the velocity
coordinate is the body-frame vector ω̄; the Euler parameter rates follow from
(Nikravesh 1988, Eqs. 6.101 and 6.104)::

    ṗ = ½ L(p)ᵀ ω̄,   L(p) = [−e, −ẽ + e0 I]  (3×4),   ω̄ = 2 L(p) ṗ.

A finite body-frame rotation increment Δθ is applied by the quaternion product
``p ⊕ Δθ = p ⊗ exp(Δθ/2)``, which keeps ``|p| = 1`` exactly (the retraction used by the
Lie-group integrators and Newton updates).

References
----------
P. E. Nikravesh, *Computer-Aided Analysis of Mechanical Systems*, Prentice Hall, 1988, Ch. 6.
O. Brüls, A. Cardona, "On the use of Lie group time integrators in multibody dynamics",
J. Comput. Nonlinear Dynam. 5 (2010) 031002.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

#: Planar 90° rotation R with dA/dθ = A R.
ROT90 = np.array([[0.0, -1.0], [1.0, 0.0]])


def rot2(theta: ArrayLike) -> NDArray[np.float64]:
    """Planar rotation matrices.

    Parameters
    ----------
    theta : array_like, shape (...)
        Angles [rad].

    Returns
    -------
    ndarray, shape (..., 2, 2)
    """
    th = np.asarray(theta, dtype=float)
    c, s = np.cos(th), np.sin(th)
    out = np.empty(th.shape + (2, 2))
    out[..., 0, 0] = c
    out[..., 0, 1] = -s
    out[..., 1, 0] = s
    out[..., 1, 1] = c
    return out


def skew(v: ArrayLike) -> NDArray[np.float64]:
    """Skew-symmetric cross-product matrices ``ṽ`` with ``ṽ x = v × x``.

    Parameters
    ----------
    v : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    v = np.asarray(v, dtype=float)
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1] = -v[..., 2]
    out[..., 0, 2] = v[..., 1]
    out[..., 1, 0] = v[..., 2]
    out[..., 1, 2] = -v[..., 0]
    out[..., 2, 0] = -v[..., 1]
    out[..., 2, 1] = v[..., 0]
    return out


def euler_to_matrix(p: ArrayLike) -> NDArray[np.float64]:
    """Rotation matrices from Euler parameters, ``A = (2e0²−1)I + 2(eeᵀ + e0 ẽ)``.

    Parameters
    ----------
    p : array_like, shape (..., 4)
        Euler parameters (e0, e1, e2, e3); assumed normalised.

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    p = np.asarray(p, dtype=float)
    e0, e1, e2, e3 = p[..., 0], p[..., 1], p[..., 2], p[..., 3]
    out = np.empty(p.shape[:-1] + (3, 3))
    out[..., 0, 0] = 2.0 * (e0 * e0 + e1 * e1) - 1.0
    out[..., 0, 1] = 2.0 * (e1 * e2 - e0 * e3)
    out[..., 0, 2] = 2.0 * (e1 * e3 + e0 * e2)
    out[..., 1, 0] = 2.0 * (e1 * e2 + e0 * e3)
    out[..., 1, 1] = 2.0 * (e0 * e0 + e2 * e2) - 1.0
    out[..., 1, 2] = 2.0 * (e2 * e3 - e0 * e1)
    out[..., 2, 0] = 2.0 * (e1 * e3 - e0 * e2)
    out[..., 2, 1] = 2.0 * (e2 * e3 + e0 * e1)
    out[..., 2, 2] = 2.0 * (e0 * e0 + e3 * e3) - 1.0
    return out


def matrix_to_euler(A: ArrayLike) -> NDArray[np.float64]:
    """Euler parameters (e0 ≥ 0) of a rotation matrix (Shepperd's method, vectorised).

    Parameters
    ----------
    A : array_like, shape (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 4)
    """
    A = np.asarray(A, dtype=float)
    tr = np.trace(A, axis1=-2, axis2=-1)
    diag = np.stack([tr, A[..., 0, 0], A[..., 1, 1], A[..., 2, 2]], axis=-1)
    k = np.argmax(diag, axis=-1)
    p = np.empty(A.shape[:-2] + (4,))
    # each branch computed everywhere then selected; numerically safe since the divisor is the
    # largest of the four candidates
    with np.errstate(divide="ignore", invalid="ignore"):
        b0 = np.stack(
            [
                1.0 + tr,
                A[..., 2, 1] - A[..., 1, 2],
                A[..., 0, 2] - A[..., 2, 0],
                A[..., 1, 0] - A[..., 0, 1],
            ],
            axis=-1,
        )
        b1 = np.stack(
            [
                A[..., 2, 1] - A[..., 1, 2],
                1.0 + 2 * A[..., 0, 0] - tr,
                A[..., 0, 1] + A[..., 1, 0],
                A[..., 0, 2] + A[..., 2, 0],
            ],
            axis=-1,
        )
        b2 = np.stack(
            [
                A[..., 0, 2] - A[..., 2, 0],
                A[..., 0, 1] + A[..., 1, 0],
                1.0 + 2 * A[..., 1, 1] - tr,
                A[..., 1, 2] + A[..., 2, 1],
            ],
            axis=-1,
        )
        b3 = np.stack(
            [
                A[..., 1, 0] - A[..., 0, 1],
                A[..., 0, 2] + A[..., 2, 0],
                A[..., 1, 2] + A[..., 2, 1],
                1.0 + 2 * A[..., 2, 2] - tr,
            ],
            axis=-1,
        )
    cand = np.stack([b0, b1, b2, b3], axis=-2)
    sel = np.take_along_axis(cand, k[..., None, None], axis=-2)[..., 0, :]
    p = sel / np.linalg.norm(sel, axis=-1, keepdims=True)
    p = np.where(p[..., :1] < 0.0, -p, p)
    return p


def axis_angle_to_euler(axis: ArrayLike, angle: ArrayLike) -> NDArray[np.float64]:
    """Euler parameters of a rotation by ``angle`` [rad] about the unit ``axis``.

    Parameters
    ----------
    axis : array_like, shape (..., 3)
    angle : array_like, shape (...)

    Returns
    -------
    ndarray, shape (..., 4)
    """
    axis = np.asarray(axis, dtype=float)
    n = np.linalg.norm(axis, axis=-1, keepdims=True)
    if np.any(n == 0.0):
        raise ValueError(f"rotation axis {axis.tolist()} has zero length")
    half = 0.5 * np.asarray(angle, dtype=float)[..., None]
    return np.concatenate([np.cos(half), np.sin(half) * axis / n], axis=-1)


def quat_multiply(p: ArrayLike, r: ArrayLike) -> NDArray[np.float64]:
    """Quaternion product ``p ⊗ r`` (scalar first), vectorised."""
    p = np.asarray(p, dtype=float)
    r = np.asarray(r, dtype=float)
    p0, pv = p[..., :1], p[..., 1:]
    r0, rv = r[..., :1], r[..., 1:]
    s = p0 * r0 - np.sum(pv * rv, axis=-1, keepdims=True)
    v = p0 * rv + r0 * pv + np.cross(pv, rv)
    return np.concatenate([s, v], axis=-1)


def rotation_vector_to_euler(theta: ArrayLike) -> NDArray[np.float64]:
    """Exponential map: Euler parameters of the rotation vector ``θ`` (angle ``|θ|`` about θ/``|θ|``).

    Uses the series of sin(x/2)/x near zero so that small increments are exact to round-off.

    Parameters
    ----------
    theta : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 4)
    """
    theta = np.asarray(theta, dtype=float)
    ang = np.linalg.norm(theta, axis=-1, keepdims=True)
    small = ang < 1e-4
    a2 = ang * ang
    # sin(a/2)/a with Taylor fallback
    sinc_half = np.where(small, 0.5 - a2 / 48.0 + a2 * a2 / 3840.0, np.sin(0.5 * ang) / np.where(small, 1.0, ang))
    return np.concatenate([np.cos(0.5 * ang), sinc_half * theta], axis=-1)


def euler_rate_matrix(p: ArrayLike) -> NDArray[np.float64]:
    """``L(p) = [−e, −ẽ + e0 I]`` so that ω̄ = 2 L ṗ and ṗ = ½ Lᵀ ω̄.

    Parameters
    ----------
    p : array_like, shape (..., 4)

    Returns
    -------
    ndarray, shape (..., 3, 4)
    """
    p = np.asarray(p, dtype=float)
    e0 = p[..., 0]
    e = p[..., 1:]
    out = np.empty(p.shape[:-1] + (3, 4))
    out[..., :, 0] = -e
    out[..., :, 1:] = -skew(e) + e0[..., None, None] * np.eye(3)
    return out
