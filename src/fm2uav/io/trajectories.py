"""CSV tables of multi-UAV flights: time-stamped trajectories, formation metrics, cycles.

Writers only: every number comes from the caller (e.g. the fields of a
:class:`~fm2uav.missions.formation.FormationResult`). Times in seconds,
positions in world metres; three decimals (millimetres / milliseconds).

Formats
-------
``trajectories.csv``
    ``time_s, uav, x_m, y_m, z_m`` — one row per sample and UAV (long format).
``metrics.csv``
    ``time_s, min_distance_m, shape_error_m, shape_error_norm`` — one row per sample.
``cycles.csv``
    ``cycle, time_s, compute_ms, grey_f1.., goal_<uav>_x_m/_y_m/_z_m, held_<uav>`` — one
    row per re-planning cycle.
"""

from __future__ import annotations

import csv
from collections.abc import Sequence
from pathlib import Path
from typing import IO, Any

import numpy as np

from ..errors import InputError

__all__ = [
    "write_trajectories_csv",
    "read_trajectories_csv",
    "write_formation_metrics_csv",
    "write_cycles_csv",
]


def write_trajectories_csv(
    fh: IO[str], times: Any, positions: Any, names: Sequence[str]
) -> None:
    """Write time-stamped positions of several UAVs (long format).

    Parameters
    ----------
    fh : text file
        Open for writing (``newline=""`` recommended).
    times : array_like, shape (n_t,)
        Sample times [s].
    positions : array_like, shape (n_t, n_uav, 3)
        Positions [m]; ``positions[k, i]`` is UAV ``i`` at ``times[k]``.
    names : sequence of str, length n_uav
        UAV names (e.g. ``("leader", "follower 1")``).
    """
    t = np.asarray(times, dtype=float)
    pos = np.asarray(positions, dtype=float)
    if pos.ndim != 3 or pos.shape[0] != t.size or pos.shape[1] != len(names):
        raise InputError(
            f"positions must have shape (n_t={t.size}, n_uav={len(names)}, 3); got {pos.shape}")
    w = csv.writer(fh)
    w.writerow(["time_s", "uav", "x_m", "y_m", "z_m"])
    for k, tk in enumerate(t):
        for i, name in enumerate(names):
            x, y, z = pos[k, i]
            w.writerow([f"{tk:.3f}", name, f"{x:.3f}", f"{y:.3f}", f"{z:.3f}"])


def read_trajectories_csv(
    file: str | Path | IO[str],
) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """Read a file written by :func:`write_trajectories_csv`.

    Returns
    -------
    times : ndarray (n_t,)
        [s]
    positions : ndarray (n_t, n_uav, 3)
        [m]
    names : tuple of str
        In the order of their first appearance.
    """
    if isinstance(file, (str, Path)):
        from .. import _validate as _v

        _v.input_file(file, "trajectories file")  # no folder / named pipe (would block)
        with open(file, newline="", encoding="utf-8") as fh:
            return read_trajectories_csv(fh)
    rows = list(csv.DictReader(file))
    need = {"time_s", "uav", "x_m", "y_m", "z_m"}
    if not rows or not need <= set(rows[0]):
        raise InputError(f"a trajectories CSV needs the columns {sorted(need)} and data rows")
    names = tuple(dict.fromkeys(r["uav"] for r in rows))
    n = len(names)
    if len(rows) % n:
        raise InputError(f"trajectories CSV: {len(rows)} rows is not a multiple of {n} UAVs")
    times = np.array([float(r["time_s"]) for r in rows[::n]])
    pos = np.array([[float(r["x_m"]), float(r["y_m"]), float(r["z_m"])] for r in rows])
    return times, pos.reshape(len(times), n, 3), names


def write_formation_metrics_csv(
    fh: IO[str], times: Any, min_distance: Any, shape_error: Any, shape_error_norm: Any
) -> None:
    """Write the formation metrics per sample.

    Parameters
    ----------
    times : array_like (n_t,)
        [s]
    min_distance : array_like (n_t,)
        Smallest distance between two UAVs [m].
    shape_error : array_like (n_t,)
        Largest distance of a follower from its slot [m].
    shape_error_norm : array_like (n_t,)
        The same divided by the formation's size [-].
    """
    w = csv.writer(fh)
    w.writerow(["time_s", "min_distance_m", "shape_error_m", "shape_error_norm"])
    for t, d, e, en in zip(times, min_distance, shape_error, shape_error_norm, strict=True):
        w.writerow([f"{t:.3f}", f"{d:.3f}", f"{e:.3f}", f"{en:.4f}"])


def write_cycles_csv(
    fh: IO[str],
    cycle_start: Any,
    compute_s: Any,
    grey: Any,
    partial_goals: Any,
    held: Any,
    names: Sequence[str],
) -> None:
    """Write one row per re-planning cycle of a formation.

    Parameters
    ----------
    cycle_start : array_like (n_c,)
        Start time of each cycle [s].
    compute_s : array_like (n_c,)
        Wall time of each cycle [s] (written in ms).
    grey : array_like (n_c, n_followers)
        Grey level of each follower.
    partial_goals : array_like (n_c, n_uav, 3)
        Partial goal of each UAV [m].
    held : array_like of bool (n_c, n_uav)
        The UAV stayed in place that cycle.
    names : sequence of str, length n_uav
    """
    g = np.asarray(grey, dtype=float).reshape(len(cycle_start), -1)
    goals = np.asarray(partial_goals, dtype=float)
    hold = np.asarray(held, dtype=bool)
    w = csv.writer(fh)
    head = ["cycle", "time_s", "compute_ms"] + [f"grey_f{j + 1}" for j in range(g.shape[1])]
    for name in names:
        tag = name.replace(" ", "")
        head += [f"goal_{tag}_x_m", f"goal_{tag}_y_m", f"goal_{tag}_z_m", f"held_{tag}"]
    w.writerow(head)
    for c, t in enumerate(cycle_start):
        row: list[Any] = [c, f"{t:.3f}", f"{compute_s[c] * 1e3:.3f}"]
        row += [f"{b:.3f}" for b in g[c]]
        for i in range(len(names)):
            row += [f"{v:.3f}" for v in goals[c, i]] + [int(hold[c, i])]
        w.writerow(row)
