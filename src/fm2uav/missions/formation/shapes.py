"""Formation shapes and the thesis' deformation rule (eqs 6.1 / 6.2).

A shape gives every follower a nominal *slot* in the leader's frame: ``back``
(along ``-v``, behind the leader) and ``lateral`` (along ``u``, ``v`` turned
+90° in the x–y plane, i.e. to the leader's left), both in units of the safety
distance ``dist``. The thesis' triangle (ch. 6, Fig. 6.2) puts follower 1 and
follower 2 ``2·dist`` behind the leader and ``2·dist`` to either side.

Deformation (eqs 6.1 / 6.2; the extracted text is garbled, this is our reading,
which reproduces both equations): follower ``j`` with grey level
``B_j ∈ [0, 1]`` takes the slot

    lateral_j(B) = B · lateral_j
    back_j(B)    = B · back_j + (1 − B) · 2 · c_j

where ``c_j`` is the follower's rank in the fully squeezed *column* (``B = 0``:
all followers in single file behind the leader, ``2·dist`` apart). For the
triangle, follower 1 (``c = 1``) gives ``d1 = 2·dist·v``, ``d2 = 2·dist·B·u``
(eq. 6.1) and follower 2 (``c = 2``) gives ``d1 = 2·dist·(2 − B)·v``,
``d2 = −2·dist·B·u`` (eq. 6.2). With ``B = 1`` the shape is nominal; as the
grey level drops near obstacles the formation narrows and stretches into a
column, so partial goals never collapse onto each other.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ...errors import InputError

__all__ = ["FormationShape", "formation_shape", "slot_offsets", "slot_positions", "SHAPES"]

#: Names accepted by :func:`formation_shape`.
SHAPES = ("triangle", "v", "line")


@dataclass(frozen=True)
class FormationShape:
    """Nominal slots of the followers in the leader's frame.

    Attributes
    ----------
    name : str
        ``"triangle"``, ``"v"`` or ``"line"``.
    offsets : ndarray, shape (n, 2)
        ``(back, lateral)`` of each follower in units of ``dist``; back > 0 is
        behind the leader, lateral > 0 to its left.
    column : ndarray, shape (n,)
        Rank ``c_j`` (1, 2, ...) of each follower in the squeezed column.
    """

    name: str
    offsets: np.ndarray
    column: np.ndarray

    @property
    def n_followers(self) -> int:
        """Number of followers."""
        return int(self.offsets.shape[0])


def formation_shape(name: str = "triangle", n_followers: int = 2) -> FormationShape:
    """Build a formation shape.

    Parameters
    ----------
    name : {"triangle", "v", "line"}
        * ``"triangle"``: rows behind the leader; row ``r`` (``2r·dist`` back)
          holds ``r + 1`` followers ``4·dist`` apart, centred — with two
          followers this is the thesis' triangle;
        * ``"v"``: followers alternate left/right on two wings, follower ``j``
          at rank ``r = ceil(j/2)`` sits ``2r·dist`` back and ``2r·dist`` aside;
        * ``"line"``: single file (column), follower ``j`` ``2j·dist`` behind.
    n_followers : int
        Number of followers, >= 1. Default 2.

    Returns
    -------
    FormationShape

    Raises
    ------
    fm2uav.InputError
        Unknown name or ``n_followers < 1``.
    """
    key = str(name).strip().lower()
    if key not in SHAPES:
        raise InputError(f"unknown formation shape {name!r}; choose one of {', '.join(SHAPES)}")
    if isinstance(n_followers, bool) or not isinstance(n_followers, (int, np.integer)):
        raise InputError(f"n_followers must be an integer >= 1, got {n_followers!r}")
    n = int(n_followers)
    if n < 1:
        raise InputError(f"a formation needs at least one follower, got n_followers = {n}")
    offsets = np.zeros((n, 2))
    if key == "triangle":
        j, row = 0, 1
        while j < n:
            for lat in range(2 * row, -2 * row - 1, -4):  # left to right
                if j == n:
                    break
                offsets[j] = (2.0 * row, float(lat))
                j += 1
            row += 1
    elif key == "v":
        for j in range(n):
            rank = j // 2 + 1
            side = 1.0 if j % 2 == 0 else -1.0
            offsets[j] = (2.0 * rank, side * 2.0 * rank)
    else:  # line
        offsets[:, 0] = 2.0 * np.arange(1, n + 1)
    offsets.setflags(write=False)
    column = np.arange(1, n + 1, dtype=float)
    column.setflags(write=False)
    return FormationShape(name=key, offsets=offsets, column=column)


def slot_offsets(shape: FormationShape, grey: np.ndarray | float = 1.0) -> np.ndarray:
    """Deformed ``(back, lateral)`` slots, in units of ``dist`` (eqs 6.1 / 6.2).

    Parameters
    ----------
    shape : FormationShape
    grey : float or ndarray, shape (n,) or (m, n)
        Grey level ``B`` of each follower in [0, 1] (1 = nominal shape).
        With a leading axis, ``m`` candidate sets are evaluated at once.

    Returns
    -------
    ndarray, shape (n, 2) or (m, n, 2)
    """
    B = np.clip(np.asarray(grey, dtype=float), 0.0, 1.0)
    B = np.broadcast_to(B, B.shape[:-1] + (shape.n_followers,)) if B.ndim else np.full(
        shape.n_followers, float(B)
    )
    back = B * shape.offsets[:, 0] + (1.0 - B) * 2.0 * shape.column
    lateral = B * shape.offsets[:, 1]
    return np.stack([back, lateral], axis=-1)


def slot_positions(
    leader_xy: np.ndarray, heading: np.ndarray, offsets: np.ndarray, dist: float
) -> np.ndarray:
    """Horizontal slot positions [m] from the leader's pose.

    Parameters
    ----------
    leader_xy : ndarray, shape (2,)
        Leader position in the x–y plane [m].
    heading : ndarray, shape (2,)
        Unit direction ``v`` of the leader in the x–y plane.
    offsets : ndarray, shape (..., 2)
        ``(back, lateral)`` in units of ``dist``.
    dist : float
        Safety distance [m].

    Returns
    -------
    ndarray, shape (..., 2)
        ``leader − back·dist·v + lateral·dist·u`` with ``u`` = ``v`` turned +90°.
    """
    v = np.asarray(heading, dtype=float)
    u = np.array([-v[1], v[0]])
    off = np.asarray(offsets, dtype=float)
    return (
        np.asarray(leader_xy, dtype=float)
        - off[..., :1] * dist * v
        + off[..., 1:2] * dist * u
    )
