"""fm2uav.pipeline.outputs: the output-set writers shared by the CLI and the app."""

from fm2uav.io.exports import EXPORT_FILES
from fm2uav.pipeline import outputs


def test_export_file_names_are_the_exporters():
    assert outputs.EXPORT_FILES is EXPORT_FILES  # one table (fm2uav.io.formats)
    assert outputs.output_names(["plan", "html", "json"]) == ["mission.plan", "report.html",
                                                               "summary.json"]


def test_the_cli_re_exports_the_moved_names():
    from fm2uav.cli import _common, cmd_run

    assert cmd_run.plan_outputs is outputs.plan_outputs
    assert cmd_run.write_exports is outputs.write_exports
    assert _common.write_json is outputs.write_json and _common.to_jsonable is outputs.to_jsonable
