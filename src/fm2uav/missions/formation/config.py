"""The settings of a formation mission: :class:`FormationConfig`.

What the formation flies (shape, safety distance, speeds, re-planning cycle,
grey level, window). The FM² settings are the planner's own objects
(:class:`~fm2uav.Shaping`, :class:`~fm2uav.FlightLevel`,
:class:`~fm2uav.PlanOptions`), passed to :func:`~fm2uav.missions.formation.fly_formation`
next to it. Defaults that depend on the world or on other fields (``None``
below) are resolved by :meth:`FormationConfig.resolved`.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

from ... import _validate as v
from ...errors import InputError
from .shapes import SHAPES

__all__ = ["FormationConfig", "GREY_MODES", "MAX_FOLLOWERS"]

#: Largest formation (followers): each re-plans with FM² every cycle.
MAX_FOLLOWERS = 50

#: How the grey level ``B`` of a follower is measured (see ``grey_levels``).
GREY_MODES = ("goal", "follower")


def _where(name: str, flag: str | None = None) -> tuple[None, str]:
    return None, flag or "--" + name.replace("_", "-")


def _set(obj: object, name: str, value: object) -> None:
    object.__setattr__(obj, name, value)


@dataclass(frozen=True)
class FormationConfig:
    """Settings of a leader–follower formation flight (thesis ch. 6).

    Attributes
    ----------
    n_followers : int
        Number of followers, >= 1. Default 2 (the thesis' triangle of three UAVs).
    shape : {"triangle", "v", "line"}
        Nominal formation (:func:`~fm2uav.missions.formation.shapes.formation_shape`).
    dist : float
        Safety distance [m] > 0: no two UAVs ever come closer than ``dist/2``;
        the nominal triangle puts the followers ``2·dist`` behind and ``2·dist``
        to each side of the leader. Default 60 m (4 cells of the thesis' map).
    leader_speed : float
        Leader's speed [m/s] in [0.1, 300]. Default 10.
    follower_speed : float or None
        Followers' top speed [m/s] in [0.1, 300]; None: ``1.5 · leader_speed`` (so that
        they can catch up after a deformation).
    cycle : float
        Re-planning period [s] in (0, 600]. Default 1.
    clearance : float or None
        Nodes closer than this to the terrain are impassable for every UAV
        [m] > 0; None: ``2 · max(spacing)``, which keeps every path point above
        the interpolated ground.
    grey : {"goal", "follower"}
        Where the grey level is measured (``grey_levels``). Default "goal".
    grey_reference : float or None
        Horizontal clearance [m] > 0 at which ``B = 1``; None: ``2 · dist``
        (the nominal lateral offset).
    window : int
        Local re-planning window padding [cells], >= 1. Default 6.
    max_cycles : int or None
        Safety stop, >= 1; None: ``4 · ceil(leader path length / (leader_speed ·
        cycle)) + 50``.
    settle_cycles : int or None
        Cycles allowed after the leader's arrival for the followers to reach
        their final slots, >= 0; None: ``ceil(4·dist / (follower_speed · cycle)) + 10``.

    Examples
    --------
    >>> FormationConfig(dist=45.0, n_followers=4, shape="v").dist
    45.0
    >>> FormationConfig(cycle=0)
    Traceback (most recent call last):
    ...
    fm2uav.errors.InputError: cycle must be in (0, 600] s, got 0 (CLI: --cycle)
    """

    n_followers: int = 2
    shape: str = "triangle"
    dist: float = 60.0
    leader_speed: float = 10.0
    follower_speed: float | None = None
    cycle: float = 1.0
    clearance: float | None = None
    grey: str = "goal"
    grey_reference: float | None = None
    window: int = 6
    max_cycles: int | None = None
    settle_cycles: int | None = None

    def __post_init__(self) -> None:
        _set(self, "n_followers", v.integer(self.n_followers, "n_followers", minimum=1,
                                            where=_where("n_followers", "--followers")))
        if self.n_followers > MAX_FOLLOWERS:
            raise InputError(
                f"n_followers = {self.n_followers} would re-plan {self.n_followers} FM² paths "
                f"(each a full arrival-time field) every cycle; the limit is {MAX_FOLLOWERS} "
                f"followers{v.where_text(_where('n_followers', '--followers'))}")
        _set(self, "shape", v.choice(str(self.shape).strip().lower(), tuple(SHAPES), "shape",
                                     where=_where("shape")))
        _set(self, "dist", v.positive(self.dist, "dist", unit="m", where=_where("dist")))
        # bounded: a UAV between 0.1 and 300 m/s, a re-planning cycle up to 10 min (issue 17:
        # 1e-300 m/s never arrived, 1e308 m/s overflowed)
        _set(self, "leader_speed", v.in_range(self.leader_speed, "leader_speed", 0.1, 300.0,
                                              unit="m/s",
                                              where=_where("leader_speed", "--speed")))
        _set(self, "follower_speed", v.optional(v.in_range, self.follower_speed,
                                                "follower_speed", 0.1, 300.0, unit="m/s",
                                                where=_where("follower_speed")))
        _set(self, "cycle", v.in_range(self.cycle, "cycle", 0.0, 600.0, low_open=True,
                                       unit="s", where=_where("cycle")))
        _set(self, "clearance", v.optional(v.positive, self.clearance, "clearance", unit="m"))
        v.choice(self.grey, GREY_MODES, "grey", where=_where("grey"))
        _set(self, "grey_reference", v.optional(v.positive, self.grey_reference,
                                                "grey_reference", unit="m"))
        _set(self, "window", v.integer(self.window, "window (cells)", minimum=1))
        _set(self, "max_cycles", v.optional(v.integer, self.max_cycles, "max_cycles",
                                            minimum=1))
        _set(self, "settle_cycles", v.optional(v.integer, self.settle_cycles,
                                               "settle_cycles", minimum=0))

    def resolved(self, spacing: tuple[float, ...]) -> FormationConfig:
        """A copy with the defaults that depend on other fields or on the grid
        ``spacing`` [m] filled in (``follower_speed``, ``clearance``,
        ``grey_reference``); ``max_cycles`` / ``settle_cycles`` need the
        leader's path and are filled in by the mission."""
        return dataclasses.replace(
            self,
            follower_speed=(1.5 * self.leader_speed if self.follower_speed is None
                            else self.follower_speed),
            clearance=2.0 * float(max(spacing)) if self.clearance is None else self.clearance,
            grey_reference=2.0 * self.dist if self.grey_reference is None else self.grey_reference,
        )
