"""fm2uav.errors: the hierarchy and what an error means to a user (CLI and app alike)."""

import errno
import json

import pytest

from fm2uav import errors
from fm2uav.errors import (EXIT_INPUT, EXIT_PLANNING, InputError, PlanningError, PointError,
                           UnreachableError, describe_error)


@pytest.mark.parametrize("exc, code", [
    (InputError("bad"), EXIT_INPUT), (PointError("p"), EXIT_INPUT),
    (PlanningError("x"), EXIT_PLANNING), (UnreachableError("u"), EXIT_PLANNING),
])
def test_fm2uav_errors_keep_their_message(exc, code):
    assert describe_error(exc) == (str(exc), code)


def test_environment_errors_are_named_and_bugs_are_not():
    assert describe_error(FileNotFoundError(errno.ENOENT, "x", "/a/b")) == (
        "file not found: /a/b; check the path", EXIT_INPUT)
    msg, code = describe_error(json.JSONDecodeError("Expecting value", "{", 1))
    assert code == EXIT_INPUT and "not valid JSON" in msg
    assert describe_error(KeyError("x")) is None


def test_the_cli_shows_the_same_function():
    from fm2uav.cli import _common

    assert _common.describe_error is errors.describe_error
    assert (_common.EXIT_INTERNAL, _common.EXIT_INTERRUPTED) == (70, 130)
