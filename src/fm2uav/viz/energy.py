"""The report of a power-model fit (``fm2uav calibrate --report``): measured and modelled
power along the log, and the residual, as one self-contained plotly page."""

from __future__ import annotations

import html
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np

__all__ = ["calibration_report_html"]


def calibration_report_html(samples: Any, model: Any, rows: Mapping[str, Any], *, title: str,
                            files: Sequence[str] = ()) -> str:
    """report.html of a fit: the figures of ``rows`` first, then the battery power measured in
    the log and the fitted ``model``'s power at the logged airspeed and climb [W] over time
    [s], and the residual.

    Parameters
    ----------
    samples : fm2uav.vehicles.calibration.PowerSamples
        The log's samples (``t``, ``power``, ``airspeed``, ``climb``).
    model : PowerModel
        The fitted model (``model.power(airspeed, climb)`` in W).
    rows : mapping
        The printed summary rows (shown as the operator's figures).
    title : str
    files : sequence of str
        The files written beside the report.
    """
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    t = np.asarray(samples.t, dtype=float)
    measured = np.asarray(samples.power, dtype=float)
    modelled = np.asarray(model.power(np.asarray(samples.airspeed, dtype=float),
                                      np.asarray(samples.climb, dtype=float)), dtype=float)
    fig = make_subplots(rows=2, cols=1, shared_xaxes=True, row_heights=[0.7, 0.3],
                        subplot_titles=("battery power [W]", "measured − model [W]"))
    fig.add_trace(go.Scattergl(x=t, y=measured, mode="markers", name="measured",
                               marker={"size": 3, "color": "#555"}), row=1, col=1)
    fig.add_trace(go.Scattergl(x=t, y=modelled, mode="lines", name="fitted model",
                               line={"color": "#d62728", "width": 2}), row=1, col=1)
    fig.add_trace(go.Scattergl(x=t, y=measured - modelled, mode="markers", name="residual",
                               marker={"size": 3, "color": "#1f77b4"}), row=2, col=1)
    fig.update_xaxes(title_text="time in the log [s]", row=2, col=1)
    fig.update_layout(height=640, margin={"l": 60, "r": 20, "t": 40, "b": 50})
    table = "".join(f"<tr><th>{html.escape(str(k))}</th><td>{html.escape(str(v))}</td></tr>"
                    for k, v in rows.items())
    listed = "".join(f"<li>{html.escape(f)}</li>" for f in files)
    return ("<!DOCTYPE html><html lang='en'><head><meta charset='utf-8'>"
            f"<title>{html.escape(title)}</title><style>body{{font:14px system-ui,sans-serif;"
            "margin:1.5em}th{text-align:left;padding-right:1em}</style></head><body>"
            f"<h1>{html.escape(title)}</h1><table>{table}</table>"
            + fig.to_html(full_html=False, include_plotlyjs=True)
            + (f"<h2>Files</h2><ul>{listed}</ul>" if listed else "") + "</body></html>")
