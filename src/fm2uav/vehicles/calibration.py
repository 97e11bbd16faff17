"""Fit an airframe's power model to the power measured in a flight log.

The models of :mod:`.power` are linear in their coefficients, ``P = Φ(V, Vz) c``, so
the fit is a bounded linear least-squares problem (:func:`scipy.optimize.lsq_linear`,
every coefficient ≥ 0) over the samples of a log (battery voltage × current against
airspeed and climb rate, :func:`fm2uav.io.flightlog.read_power_samples`). Samples whose
power sits at the model's floor (the avionics power) are not used.

Coefficients a log cannot tell apart are held at the model's values (``fit`` names
the free ones): by default the avionics power, whose constant is indistinguishable
in flight from the constant part of a multirotor's profile power (or, over a
fixed-wing's narrow speed range, from its drag terms), and any coefficient whose
shape the log never excites (no descent in the log: the descent term is kept).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from ..errors import InputError
from .power import PowerModel

__all__ = ["PowerSamples", "Calibration", "fit_power"]


@dataclass(frozen=True)
class PowerSamples:
    """Time series of a flight for the fit (same length each).

    Attributes
    ----------
    t : ndarray
        Time [s].
    power : ndarray
        Electrical power at the battery, voltage × current [W].
    airspeed : ndarray
        True airspeed [m/s] (the ground speed where the log has none: calm air).
    climb : ndarray
        Climb rate [m/s], positive up.
    groundspeed : ndarray
        Horizontal ground speed [m/s].
    source : str
        The log and the messages read.
    """

    t: np.ndarray
    power: np.ndarray
    airspeed: np.ndarray
    climb: np.ndarray
    groundspeed: np.ndarray
    source: str = ""

    def __post_init__(self) -> None:
        n = len(self.t)
        for name in ("power", "airspeed", "climb", "groundspeed"):
            if len(getattr(self, name)) != n:
                raise InputError(f"power samples: {name} has {len(getattr(self, name))} "
                                 f"values for {n} times")

    def __len__(self) -> int:
        return len(self.t)


@dataclass(frozen=True)
class Calibration:
    """A fitted power model and how well it fits.

    Attributes
    ----------
    model : MultirotorPower or FixedWingPower
        The model with the fitted coefficients (its physical parameters read back).
    coefficients : dict of str to float
        The fitted linear coefficients by name.
    free : list of str
        The coefficients that were fitted (the others held).
    samples : int
        Samples used.
    rms_w : float
        Root-mean-square residual [W].
    r2 : float
        Coefficient of determination of the fit.
    """

    model: PowerModel
    coefficients: dict[str, float]
    free: list[str]
    samples: int
    rms_w: float
    r2: float

    def summary(self) -> dict[str, Any]:
        """JSON-friendly result."""
        return {"model": self.model.summary(), "coefficients": self.coefficients,
                "free": self.free, "samples": self.samples, "rms_w": round(self.rms_w, 3),
                "r2": round(self.r2, 5)}


def fit_power(model: PowerModel, samples: PowerSamples, *,
              fit: Sequence[str] | None = None, min_samples: int = 20) -> Calibration:
    """Least-squares fit of ``model``'s coefficients to measured power.

    Parameters
    ----------
    model : MultirotorPower or FixedWingPower
        The starting model: its mass, areas and density fix the shapes; held
        coefficients keep its values.
    samples : PowerSamples
        The flight's samples.
    fit : sequence of str, optional
        Names of the coefficients to fit (``model.COEFFICIENTS``); default all but
        ``avionics_w``. Those the samples do not excite are held anyway.
    min_samples : int
        Fewest samples accepted.

    Returns
    -------
    Calibration

    Raises
    ------
    InputError
        Too few usable samples, an unknown coefficient name, or a fit that gives an
        impossible model (e.g. an efficiency above 100 %).
    """
    from scipy.optimize import lsq_linear

    names = list(model.COEFFICIENTS)
    free = [n for n in names if n != "avionics_w"] if fit is None else list(fit)
    unknown = [n for n in free if n not in names]
    if unknown:
        raise InputError(f"unknown coefficient(s) {unknown}; the {model.kind} model has: "
                         f"{', '.join(names)}")
    good = (np.isfinite(samples.power) & np.isfinite(samples.airspeed)
            & np.isfinite(samples.climb) & (samples.power > model.avionics_w))
    if model.kind == "fixed-wing":
        good &= samples.airspeed > 1.0
    if int(good.sum()) < min_samples:
        raise InputError(f"the log has {int(good.sum())} usable power samples (flying, with "
                         f"voltage, current, speed and climb); at least {min_samples} needed")
    phi = model.basis(samples.airspeed[good], samples.climb[good])
    y = samples.power[good]
    c0 = model.coefficients()
    size = np.max(np.abs(phi), axis=0)
    varies = np.ptp(phi, axis=0) > 1e-9 * size
    excited = (size > 0) & (varies | (np.array(names) == "avionics_w"))
    idx = [names.index(n) for n in free if excited[names.index(n)]]
    held = [j for j in range(len(names)) if j not in idx]
    target = y - phi[:, held] @ c0[held]
    scale = np.maximum(np.linalg.norm(phi[:, idx], axis=0), 1e-300)
    res = lsq_linear(phi[:, idx] / scale, target, bounds=(0.0, np.inf), method="bvls",
                     lsmr_tol="auto")
    c = c0.copy()
    c[idx] = res.x / scale
    fitted = model.with_coefficients(c)
    resid = y - phi @ c
    ss = float(np.sum((y - y.mean()) ** 2))
    return Calibration(fitted, {n: float(v) for n, v in zip(names, c)},
                       [names[j] for j in idx], int(good.sum()),
                       float(np.sqrt(np.mean(resid ** 2))),
                       1.0 - float(np.sum(resid ** 2)) / ss if ss > 0 else 1.0)
