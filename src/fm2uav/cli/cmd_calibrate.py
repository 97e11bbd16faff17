"""``fm2uav calibrate``: fit an airframe's power model to a flight log."""

from __future__ import annotations

from pathlib import Path

import typer

from ._common import Output, handle_errors, write_json, write_text
from .options import output_options

CALIBRATE_FILES = ("power.yaml", "calibration.json")


def _help() -> str:
    return (
        "Fit the power model of an airframe to the power measured in a flight log: ArduPilot "
        "(.tlog from the ground station: SYS_STATUS/BATTERY_STATUS and VFR_HUD; .bin from "
        "the SD card: BAT, ARSP, GPS) or PX4 (.ulg: battery_status, airspeed_validated, "
        "vehicle_local_position, vehicle_status): battery voltage x current against airspeed "
        "and climb "
        "rate, linear least squares over the model's coefficients. Writes power.yaml (give "
        "it to --power or airframe.power: the energy of every later mission uses it) and "
        "calibration.json (coefficients, residual, R²).\n\n"
        "Examples:\n\n"
        "  fm2uav calibrate flight.tlog --power arducopter --mass 2.4 --out out/calib\n\n"
        "  fm2uav calibrate 00000042.BIN --power disco --fit cd0/efficiency --fit "
        "k/efficiency --out out/calib\n\n"
        "  fm2uav calibrate log_12_2026-5-4-10-20-31.ulg --power crosswind --out out/calib\n\n"
        "The starting model fixes the mass, areas and air density; fly level legs at several "
        "speeds, climbs and descents so that every term shows in the log."
    )


@handle_errors
@output_options("out/calibrate", json_help="Print the fit as JSON.",
                report_help="Also write report.html: measured and fitted power along the log.")
def calibrate_cmd(
    log_file: Path = typer.Argument(..., help="Flight log: ArduPilot .tlog or .bin, PX4 .ulg.",
                                    show_default=False),
    power: str = typer.Option(
        "arducopter", help="Starting power model: a preset (arducopter, disco, crosswind) or "
        "a .yaml/.json file; its mass, areas and density are kept."),
    mass: float | None = typer.Option(
        None, help="Take-off mass (kg) of the logged flight, if not the starting model's: the "
        "shapes of the induced and climb terms depend on it."),
    fit: list[str] | None = typer.Option(
        None, "--fit", help="A coefficient to fit (repeat); default all but avionics_w.",
        show_default=False),
    output: Output = None,
) -> None:
    """``fm2uav calibrate``: read the log, :func:`~fm2uav.vehicles.calibration.fit_power`,
    write power.yaml and calibration.json, print."""
    import yaml

    from ..io.flightlog import read_power_samples
    from ..vehicles.calibration import fit_power
    from ..vehicles.power import get_power_model

    from ..errors import InputError

    start = get_power_model(power)
    if mass is not None and not mass > 0:
        raise InputError(f"--mass must be a take-off mass > 0 kg, got {mass}")
    if mass is not None:
        from dataclasses import replace

        start = replace(start, mass_kg=mass)
    outdir = output.dir(CALIBRATE_FILES + (("report.html",) if output.report else ()))
    with output.progress() as step:
        step(f"reading {log_file.name}")
        samples = read_power_samples(log_file)
        step(f"fitting the {start.kind} model to {len(samples)} samples")
        cal = fit_power(start, samples, fit=fit)
    model = cal.model.summary()
    model["source"] = (f"fitted to {log_file.name} ({samples.source}; {cal.samples} samples, "
                       f"rms {cal.rms_w:.2f} W) from {start.name}")
    write_text(outdir, "power.yaml", yaml.safe_dump(model, sort_keys=False))
    payload = {**cal.summary(), "model": model, "log": str(log_file)}
    write_json(outdir, "calibration.json", payload)
    rows = {"log": f"{log_file} ({samples.source})", "samples used": cal.samples,
            **{f"fitted {k}" if k in cal.free else f"held {k}": f"{v:.5g}"
               for k, v in cal.coefficients.items()},
            "rms residual [W]": f"{cal.rms_w:.2f}", "R²": f"{cal.r2:.4f}",
            "efficiency": f"{cal.model.efficiency:.3f}"}
    if cal.model.kind == "multirotor":
        rows["hover power [W]"] = f"{cal.model.hover_power():.1f}"
    if output.report:
        from ..viz.energy import calibration_report_html

        write_text(outdir, "report.html", calibration_report_html(
            samples, cal.model, rows, title=f"fm2uav calibrate — {log_file.name}",
            files=list(CALIBRATE_FILES)))
    output.summary("power model fit", rows, payload)


def register(app: typer.Typer, reproduce_app: typer.Typer) -> None:
    """Add the ``calibrate`` command."""
    app.command("calibrate", help=_help())(calibrate_cmd)
