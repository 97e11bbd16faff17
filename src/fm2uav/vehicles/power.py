"""Electrical power of an airframe versus airspeed and climb rate.

Both models are sums of physical terms, each a known *shape* of the flight state
(airspeed ``V`` [m/s], climb rate ``Vz`` [m/s], positive up) times one coefficient:

``P(V, Vz) = Σ_j c_j · φ_j(V, Vz)``  [W, electrical, at the battery]

so the coefficients ``c_j`` can be fitted to a flight log by linear least squares
(:mod:`.calibration`) and read back as physical parameters
(:meth:`MultirotorPower.with_coefficients`). The power never drops below the
avionics power (a motor does not give energy back).

Multirotor (momentum theory, Leishman *Principles of Helicopter Aerodynamics*
ch. 2 and 5; the same three terms as Zeng, Xu & Zhang, "Energy minimization for
wireless communication with rotary-wing UAV", IEEE TWC 2019, eq. 12):

* induced: ``κ/η · T v_i`` with the thrust ``T = m g`` and the induced velocity
  ``v_i`` solving ``v_i = v_h² / sqrt(V² + (Vz + v_i)²)``, ``v_h = sqrt(T / (2 ρ A))``
  (uniform inflow, small disk tilt; in level flight the closed form
  ``v_i² = sqrt(V⁴/4 + v_h⁴) − V²/2``; valid for descents slower than about ``v_h``,
  ~6 m/s for the preset — faster ones enter the vortex ring state, not modelled);
* blade profile: ``P0/η · (1 + 3 V² / U_tip²)``;
* parasite (fuselage drag): ``CdA/η · ½ ρ V³``;
* climb: ``1/η · T Vz`` when climbing, ``r/η · T Vz`` when descending (a share ``r``
  of the potential-energy rate comes back as less rotor power);
* avionics: ``P_av``.

Fixed-wing (drag polar ``CD = CD0 + k CL²``, lift = weight, Anderson *Aircraft
Performance and Design* §5.4):

* parasite: ``CD0/η · ½ ρ S V³``;
* induced: ``k/η · W² / (½ ρ S V)``;
* climb ``1/η · W Vz`` and descent ``r/η · W Vz``; avionics ``P_av``.

``η`` is the battery-to-air efficiency (ESC × motor × propeller). Turns (the load
factor ``1/cos φ`` on the induced term), accelerations and the air density's change
with altitude are not modelled; ``air_density`` is a parameter (ISA sea level by
default, :func:`isa_density` for another altitude).

Presets (:data:`POWER_MODELS`, one per electric airframe of
:data:`~fm2uav.vehicles.airframes.AIRFRAMES`; ``plane-jet`` burns fuel and has none).
Their numbers are class estimates, each with its reason in ``source``; fit your own
vehicle's from a flight log (:func:`fm2uav.vehicles.calibration.fit_power`):

==============  ======  ======================================================
preset           hover / cruise power, battery   (``fm2uav`` computes them)
==============  ======  ======================================================
``arducopter``   2.0 kg quad, 10" props, 4S 5000 mAh (74 Wh)
``disco``        Parrot Disco, 0.94 kg, 3S 2700 mAh (30 Wh)
``crosswind``    MFD Crosswind VTOL in plane mode, 4.5 kg, 6S 10 Ah (222 Wh)
==============  ======  ======================================================
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any

import numpy as np

from ..errors import InputError
from .airframes import G

__all__ = [
    "RHO0",
    "isa_density",
    "MultirotorPower",
    "FixedWingPower",
    "PowerModel",
    "POWER_MODELS",
    "get_power_model",
    "induced_velocity",
]

#: ISA sea-level air density [kg/m³].
RHO0 = 1.225


def isa_density(altitude_m: float) -> float:
    """ISA troposphere air density [kg/m³] at a pressure altitude [m] (0–11 km).

    Examples
    --------
    >>> round(isa_density(0.0), 3), round(isa_density(1000.0), 3)
    (1.225, 1.112)
    """
    h = float(altitude_m)
    if not (-500.0 <= h <= 11000.0):
        raise InputError(f"altitude must be in [-500, 11000] m for the ISA troposphere, got {h}")
    return RHO0 * (1.0 - 2.25577e-5 * h) ** 4.2559


def _check(name: str, value: Any, *, low: float = 0.0, allow_low: bool = False,
           high: float = math.inf) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise InputError(f"power model {name} must be a number, got {value!r}") from None
    ok = math.isfinite(v) and (v >= low if allow_low else v > low) and v <= high
    if not ok:
        rng = f"{'>=' if allow_low else '>'} {low:g}" + ("" if high == math.inf else
                                                         f" and <= {high:g}")
        raise InputError(f"power model {name} must be finite and {rng}, got {value!r} "
                         "(airframe.power in the mission file)")
    return v


#: Halvings of :func:`induced_velocity`'s bisection (the bracket shrinks to machine precision).
_HALVINGS = 60

#: Up to this many states, :func:`induced_velocity` bisects each with Python floats (no
#: numba import for a take-off, a landing or a hover); more go to the compiled loop
#: (``_power_kernels.bisect_induced``): the same IEEE operations, bit for bit.
_SCALAR_STATES = 4


def induced_velocity(airspeed: Any, climb: Any, hover_induced: float) -> np.ndarray:
    """Rotor induced velocity ``v_i`` [m/s] from momentum theory.

    Solves ``v_i · sqrt(V² + (Vz + v_i)²) = v_h²`` for ``v_i > 0`` by bisection on
    ``[0, v_h + |Vz|]`` (60 halvings, to machine precision). Each state is solved on its own
    (the result of one does not depend on the others it is given with), a few states with
    Python floats, more in a compiled loop: the same result, bit for bit.

    Examples
    --------
    >>> float(induced_velocity(0.0, 0.0, 6.0)[()])        # hover: v_i = v_h
    6.0
    >>> v = float(induced_velocity(10.0, 0.0, 6.0)[()])   # level: closed form
    >>> round(v, 9) == round(math.sqrt(math.sqrt(10**4 / 4 + 6**4) - 10**2 / 2), 9)
    True
    """
    v = np.asarray(airspeed, dtype=float)
    vz = np.asarray(climb, dtype=float)
    v, vz = np.broadcast_arrays(v, vz)
    vh = float(hover_induced)
    if v.size <= _SCALAR_STATES:
        return np.array([_bisect(a, c, vh) for a, c in zip(v.flat, vz.flat)],
                        dtype=float).reshape(v.shape)
    from ._power_kernels import bisect_induced

    out = np.empty(v.size)
    # copies: writeable and contiguous whatever the input (one compiled specialisation)
    bisect_induced(np.array(v).ravel(), np.array(vz).ravel(), vh, vh ** 2, _HALVINGS, out)
    return out.reshape(v.shape)


def _bisect(v: float, vz: float, vh: float) -> float:
    """:func:`induced_velocity` of one state, with Python floats (the same operations)."""
    v2, vh2 = v * v, vh ** 2
    lo, hi = 0.0, vh + abs(vz)
    for _ in range(_HALVINGS):
        mid = 0.5 * (lo + hi)
        s = vz + mid
        if mid * math.sqrt(v2 + s * s) < vh2:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


class _Linear:
    """Shared machinery: ``P = max(basis @ coefficients, avionics)``."""

    #: Names of the linear coefficients, in the order of :meth:`basis`.
    COEFFICIENTS: tuple[str, ...] = ()
    avionics_w: float
    battery_wh: float
    name: str

    def basis(self, airspeed: Any, climb: Any) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def coefficients(self) -> np.ndarray:  # pragma: no cover - abstract
        raise NotImplementedError

    def with_coefficients(self, c: Any) -> Any:  # pragma: no cover - abstract
        raise NotImplementedError

    def power(self, airspeed: Any, climb: Any = 0.0) -> np.ndarray:
        """Electrical power [W] at airspeed [m/s] and climb rate [m/s] (arrays broadcast)."""
        p = self.basis(airspeed, climb) @ self.coefficients()
        return np.maximum(p, self.avionics_w)

    def best_range_speed(self, low: float, high: float) -> float:
        """Airspeed [m/s] in ``[low, high]`` of least energy per metre in still air."""
        v = np.linspace(max(low, 0.1), high, 2001)
        return float(v[np.argmin(self.power(v, 0.0) / v)])

    def minimum_power_speed(self, low: float, high: float) -> float:
        """Airspeed [m/s] in ``[low, high]`` of least power (longest endurance), level."""
        v = np.linspace(max(low, 0.0), high, 2001)
        return float(v[np.argmin(self.power(v, 0.0))])

    def summary(self) -> dict[str, Any]:
        """JSON-friendly parameters, with ``kind`` (what :func:`get_power_model` reads back)."""
        return {"kind": self.kind,  # type: ignore[attr-defined]
                **{f.name: getattr(self, f.name) for f in fields(self)}}  # type: ignore[arg-type]


@dataclass(frozen=True)
class MultirotorPower(_Linear):
    """Momentum-theory power of a multirotor (module docstring).

    Attributes
    ----------
    name : str
    mass_kg : float
        Take-off mass [kg].
    disk_area_m2 : float
        Total rotor disk area ``A`` [m²] (rotors × π R²).
    tip_speed_mps : float
        Blade tip speed in hover ``U_tip`` [m/s].
    induced_factor : float
        ``κ`` (≥ 1): induced power over the ideal momentum-theory one.
    profile_power_w : float
        Blade profile power in hover ``P0`` [W, mechanical].
    drag_area_m2 : float
        Fuselage drag area ``CdA`` [m²].
    efficiency : float
        ``η`` in (0, 1]: battery-to-rotor efficiency (ESC × motor).
    descent_recovery : float
        ``r`` in [0, 1]: share of the potential-energy rate given back in descent.
    avionics_w : float
        Constant electrical load [W] (flight controller, radios, payload).
    battery_wh : float
        Usable-when-full battery energy [Wh] (nominal voltage × capacity).
    max_tilt_deg : float
        Largest lean angle [deg] (ArduCopter ``ANGLE_MAX``): bounds the airspeed,
        :meth:`max_airspeed`.
    air_density : float
        ρ [kg/m³].
    source : str
        Where the numbers come from.
    """

    name: str
    mass_kg: float
    disk_area_m2: float
    tip_speed_mps: float
    induced_factor: float
    profile_power_w: float
    drag_area_m2: float
    efficiency: float
    descent_recovery: float
    avionics_w: float
    battery_wh: float
    max_tilt_deg: float = 30.0
    air_density: float = RHO0
    source: str = ""

    kind = "multirotor"
    COEFFICIENTS = ("induced_factor/efficiency", "profile_power_w/efficiency",
                    "drag_area_m2/efficiency", "1/efficiency (climb)",
                    "descent_recovery/efficiency", "avionics_w")

    def __post_init__(self) -> None:
        for f, lo, allow, hi in (("mass_kg", 0, False, math.inf),
                                 ("disk_area_m2", 0, False, math.inf),
                                 ("tip_speed_mps", 0, False, math.inf),
                                 ("induced_factor", 0, False, math.inf),
                                 ("profile_power_w", 0, True, math.inf),
                                 ("drag_area_m2", 0, True, math.inf),
                                 ("efficiency", 0, False, 1.0),
                                 ("descent_recovery", 0, True, 1.0),
                                 ("avionics_w", 0, True, math.inf),
                                 ("battery_wh", 0, False, math.inf),
                                 ("max_tilt_deg", 0, False, 89.0),
                                 ("air_density", 0, False, 2.0)):
            object.__setattr__(self, f, _check(f, getattr(self, f), low=lo, allow_low=allow,
                                               high=hi))

    @property
    def thrust_n(self) -> float:
        """Thrust in level flight: the weight ``m g`` [N]."""
        return self.mass_kg * G

    @property
    def hover_induced_mps(self) -> float:
        """Hover induced velocity ``v_h = sqrt(T / (2 ρ A))`` [m/s]."""
        return math.sqrt(self.thrust_n / (2.0 * self.air_density * self.disk_area_m2))

    def basis(self, airspeed: Any, climb: Any) -> np.ndarray:
        """The shapes ``φ_j(V, Vz)``, shape ``(*broadcast, 6)`` (:attr:`COEFFICIENTS`)."""
        v, vz = np.broadcast_arrays(np.asarray(airspeed, float), np.asarray(climb, float))
        t = self.thrust_n
        vi = induced_velocity(v, vz, self.hover_induced_mps)
        return np.stack([t * vi, 1.0 + 3.0 * v * v / self.tip_speed_mps ** 2,
                         0.5 * self.air_density * v ** 3, t * np.maximum(vz, 0.0),
                         t * np.minimum(vz, 0.0), np.ones(v.shape)], axis=-1)

    def coefficients(self) -> np.ndarray:
        """The linear coefficients ``c_j`` (:attr:`COEFFICIENTS`)."""
        e = self.efficiency
        return np.array([self.induced_factor / e, self.profile_power_w / e,
                         self.drag_area_m2 / e, 1.0 / e, self.descent_recovery / e,
                         self.avionics_w])

    def with_coefficients(self, c: Any) -> MultirotorPower:
        """The model whose linear coefficients are ``c`` (the efficiency from the climb one).

        Raises
        ------
        InputError
            A climb coefficient not >= 1 (efficiency above 1) or another out of range.
        """
        c = np.asarray(c, dtype=float)
        if not c[3] >= 1.0:
            raise InputError(f"fitted climb coefficient 1/efficiency = {c[3]:.3g} < 1 (an "
                             "efficiency above 100 %): the log has too little climbing to "
                             "tell; fit without it (fit= leaves it out) or fly climbs")
        e = 1.0 / c[3]
        return replace(self, induced_factor=c[0] * e, profile_power_w=c[1] * e,
                       drag_area_m2=c[2] * e, efficiency=e,
                       descent_recovery=min(c[4] * e, 1.0), avionics_w=c[5])

    def hover_power(self) -> float:
        """Electrical power in hover [W]."""
        return float(self.power(0.0, 0.0))

    def max_airspeed(self) -> float:
        """Airspeed [m/s] at which the drag needs the largest lean: ``½ρ CdA V² = m g tan θ``."""
        if self.drag_area_m2 <= 0:
            return math.inf
        return math.sqrt(2.0 * self.thrust_n * math.tan(math.radians(self.max_tilt_deg))
                         / (self.air_density * self.drag_area_m2))


@dataclass(frozen=True)
class FixedWingPower(_Linear):
    """Drag-polar power of a fixed-wing (module docstring).

    Attributes
    ----------
    name : str
    mass_kg : float
        Flying mass [kg].
    wing_area_m2 : float
        Reference wing area ``S`` [m²].
    cd0 : float
        Zero-lift drag coefficient ``CD0``.
    k : float
        Induced drag factor ``k = 1 / (π e AR)``.
    efficiency : float
        ``η`` in (0, 1]: battery-to-thrust-power efficiency (ESC × motor × propeller).
    descent_recovery : float
        ``r`` in [0, 1]: share of the potential-energy rate that lowers the power in
        descent (1: a clean glide, the throttle pulled back).
    avionics_w : float
        Constant electrical load [W].
    battery_wh : float
        Battery energy [Wh].
    air_density : float
        ρ [kg/m³].
    source : str
        Where the numbers come from.
    """

    name: str
    mass_kg: float
    wing_area_m2: float
    cd0: float
    k: float
    efficiency: float
    descent_recovery: float
    avionics_w: float
    battery_wh: float
    air_density: float = RHO0
    source: str = ""

    kind = "fixed-wing"
    COEFFICIENTS = ("cd0/efficiency", "k/efficiency", "1/efficiency (climb)",
                    "descent_recovery/efficiency", "avionics_w")

    def __post_init__(self) -> None:
        for f, lo, allow, hi in (("mass_kg", 0, False, math.inf),
                                 ("wing_area_m2", 0, False, math.inf),
                                 ("cd0", 0, False, 1.0), ("k", 0, True, 1.0),
                                 ("efficiency", 0, False, 1.0),
                                 ("descent_recovery", 0, True, 1.0),
                                 ("avionics_w", 0, True, math.inf),
                                 ("battery_wh", 0, False, math.inf),
                                 ("air_density", 0, False, 2.0)):
            object.__setattr__(self, f, _check(f, getattr(self, f), low=lo, allow_low=allow,
                                               high=hi))

    @property
    def weight_n(self) -> float:
        """Weight ``m g`` [N]."""
        return self.mass_kg * G

    def basis(self, airspeed: Any, climb: Any) -> np.ndarray:
        """The shapes ``φ_j(V, Vz)``, shape ``(*broadcast, 5)`` (:attr:`COEFFICIENTS`).

        Raises
        ------
        InputError
            An airspeed not > 0 (a fixed-wing cannot hover).
        """
        v, vz = np.broadcast_arrays(np.asarray(airspeed, float), np.asarray(climb, float))
        if np.any(~(v > 0)):
            raise InputError("a fixed-wing's power needs airspeeds > 0 m/s")
        q_s = 0.5 * self.air_density * self.wing_area_m2
        w = self.weight_n
        return np.stack([q_s * v ** 3, w * w / (q_s * v), w * np.maximum(vz, 0.0),
                         w * np.minimum(vz, 0.0), np.ones(v.shape)], axis=-1)

    def coefficients(self) -> np.ndarray:
        """The linear coefficients ``c_j`` (:attr:`COEFFICIENTS`)."""
        e = self.efficiency
        return np.array([self.cd0 / e, self.k / e, 1.0 / e, self.descent_recovery / e,
                         self.avionics_w])

    def with_coefficients(self, c: Any) -> FixedWingPower:
        """The model whose linear coefficients are ``c`` (see :meth:`MultirotorPower.with_coefficients`)."""
        c = np.asarray(c, dtype=float)
        if not c[2] >= 1.0:
            raise InputError(f"fitted climb coefficient 1/efficiency = {c[2]:.3g} < 1 (an "
                             "efficiency above 100 %): the log has too little climbing to "
                             "tell; fit without it or fly climbs")
        e = 1.0 / c[2]
        return replace(self, cd0=c[0] * e, k=c[1] * e, efficiency=e,
                       descent_recovery=min(c[3] * e, 1.0), avionics_w=c[4])

    def stall_free_min_power_speed(self) -> float:
        """Level-flight airspeed of least power [m/s]: ``CL = sqrt(3 CD0 / k)`` (drag polar)."""
        cl = math.sqrt(3.0 * self.cd0 / self.k) if self.k > 0 else math.inf
        return math.sqrt(2.0 * self.weight_n / (self.air_density * self.wing_area_m2 * cl))


PowerModel = MultirotorPower | FixedWingPower

#: Power models of the electric presets (module docstring; every number's reason in ``source``).
POWER_MODELS: dict[str, PowerModel] = {
    "arducopter": MultirotorPower(
        "arducopter", mass_kg=2.0, disk_area_m2=4 * math.pi * 0.127 ** 2, tip_speed_mps=80.0,
        induced_factor=1.15, profile_power_w=35.0, drag_area_m2=0.04, efficiency=0.75,
        descent_recovery=1.0, avionics_w=10.0, battery_wh=74.0, max_tilt_deg=30.0,
        source="a 2 kg survey quad of the ArduCopter class: 4 x 10 inch props (R 0.127 m) at "
        "about 6000 rpm (tip 80 m/s), kappa 1.15 and profile power ~1/4 of the ideal induced "
        "power (Leishman ch. 2), drag area 0.04 m^2 (a 0.2 m^2 frame and payload, CD ~0.2), "
        "ESC x motor 0.75, descent as momentum theory (r = 1), 4S 5000 mAh LiPo (14.8 V x "
        "5 Ah = 74 Wh), ANGLE_MAX 30 deg (ArduCopter default); hover about 246 W, 123 W/kg, "
        "within the 100-150 W/kg measured on such quads"),
    "disco": FixedWingPower(
        "disco", mass_kg=0.94, wing_area_m2=0.28, cd0=0.03, k=0.085, efficiency=0.5,
        descent_recovery=1.0, avionics_w=5.0, battery_wh=30.0,
        source="Parrot Disco: 940 g with its camera (maker), 1.15 m span and about 0.28 m^2 "
        "wing (AR 4.7, e 0.8: k = 0.085), CD0 0.03 (clean flying wing), propeller x motor x "
        "ESC 0.5 (small pusher), 3S 2700 mAh (11.1 V x 2.7 Ah = 30 Wh); cruise at 14 m/s "
        "about 40 W, i.e. 37 min on 80 % of the pack against 45 min rated by the maker"),
    "crosswind": FixedWingPower(
        "crosswind", mass_kg=4.5, wing_area_m2=0.55, cd0=0.035, k=0.06, efficiency=0.55,
        descent_recovery=1.0, avionics_w=8.0, battery_wh=222.0,
        source="MFD Crosswind VTOL in plane mode: 4.5 kg with a 6S 10 Ah pack (22.2 V x 10 Ah "
        "= 222 Wh), 1.9 m span and about 0.55 m^2 wing (AR 6.6, e 0.8: k = 0.06), CD0 0.035 "
        "(the lift motors and booms add drag), propeller x motor x ESC 0.55; cruise at "
        "20 m/s about 210 W"),
}


def get_power_model(spec: Any) -> PowerModel:
    """A power model from a preset name, a parameter mapping or a file.

    Parameters
    ----------
    spec : str, Path, dict or PowerModel
        A preset of :data:`POWER_MODELS`; a ``.yaml``/``.json`` file holding a mapping
        (what ``fm2uav calibrate`` writes); or a mapping with ``preset`` (the model to
        start from) and/or ``kind`` (``multirotor`` / ``fixed-wing``) and any parameters
        of :class:`MultirotorPower` / :class:`FixedWingPower` to set. A model object is
        returned unchanged.

    Raises
    ------
    InputError
        An unknown preset, file, kind or parameter (the message lists the valid ones).

    Examples
    --------
    >>> get_power_model({"preset": "arducopter", "mass_kg": 2.5}).mass_kg
    2.5
    """
    from pathlib import Path

    from .._validate import load_json, load_yaml

    if isinstance(spec, (MultirotorPower, FixedWingPower)):
        return spec
    if isinstance(spec, (str, Path)) and Path(spec).suffix.lower() in (".yaml", ".yml", ".json"):
        path = Path(spec)
        data = (load_json(path, "power model file") if path.suffix.lower() == ".json"
                else load_yaml(path, "power model file"))
        if isinstance(data, dict) and isinstance(data.get("model"), dict):
            data = data["model"]  # a calibration result: its model
        if not isinstance(data, dict):
            raise InputError(f"power model file {path} must hold a mapping of parameters")
        return get_power_model(data)
    if isinstance(spec, dict):
        d = dict(spec)
        base = d.pop("preset", None)
        kind = d.pop("kind", None)
        if base is None and kind is None:
            raise InputError("airframe.power needs 'preset' (one of "
                             f"{', '.join(sorted(POWER_MODELS))}) or 'kind' (multirotor or "
                             "fixed-wing) with all its parameters")
        cls = {"multirotor": MultirotorPower, "fixed-wing": FixedWingPower,
               "fixed_wing": FixedWingPower}.get(str(kind)) if kind is not None else None
        if kind is not None and cls is None:
            raise InputError(f"airframe.power kind must be multirotor or fixed-wing, got {kind!r}")
        start = get_power_model(base) if base is not None else None
        if start is not None and cls is not None and not isinstance(start, cls):
            raise InputError(f"airframe.power: preset {base!r} is a {start.kind}, not a {kind}")
        cls = cls or type(start)
        names = {f.name for f in fields(cls)}
        bad = sorted(set(d) - names)
        if bad:
            raise InputError(f"airframe.power: unknown parameter(s) {bad}; a {cls.kind} "
                             f"model has: {', '.join(sorted(names))}")
        try:
            return replace(start, **d) if start is not None else cls(**d)
        except TypeError as exc:
            raise InputError(f"airframe.power: {exc} (give a preset to start from, or every "
                             "parameter)") from None
    key = str(spec).strip().lower().replace("_", "-")
    if key not in POWER_MODELS:
        raise InputError(f"no power model for airframe {spec!r}; presets with one: "
                         f"{', '.join(sorted(POWER_MODELS))}, or a .yaml/.json file of "
                         "parameters (airframe.power in the mission file, --power)")
    return POWER_MODELS[key]
