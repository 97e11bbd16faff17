"""viz/energy.py: the calibration report shows the figures and the measured vs fitted power."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from fm2uav.viz.energy import calibration_report_html


def test_the_report_draws_measured_and_model_power_and_the_residual():
    t = np.arange(5.0)
    model = SimpleNamespace(power=lambda air, climb: 100.0 + 2.0 * air + 0 * climb)
    samples = SimpleNamespace(t=t, power=np.array([100.0, 103.0, 104.0, 106.0, 108.5]),
                              airspeed=t, climb=np.zeros(5))
    page = calibration_report_html(samples, model, {"R²": "0.9990"}, title="fit <x>",
                                   files=["power.yaml"])
    assert page.startswith("<!DOCTYPE html>") and "fit &lt;x&gt;" in page
    assert "fitted model" in page and "residual" in page and "power.yaml" in page
