"""fm2uav.io.trajectories: the formation CSV writers (moved out of the CLI) and the reader."""

from __future__ import annotations

import csv
import io

import numpy as np
import pytest

from fm2uav.errors import InputError
from fm2uav.io.trajectories import (
    read_trajectories_csv,
    write_cycles_csv,
    write_formation_metrics_csv,
    write_trajectories_csv,
)

NAMES = ("leader", "follower 1")


def test_trajectories_exact_text_and_round_trip():
    t = np.array([0.0, 0.5])
    pos = np.array([[[1, 2, 3], [4, 5, 6]], [[1.0004, 2, 3], [4, 5, 6.25]]])
    buf = io.StringIO(newline="")
    write_trajectories_csv(buf, t, pos, NAMES)
    assert buf.getvalue().splitlines() == [
        "time_s,uav,x_m,y_m,z_m",
        "0.000,leader,1.000,2.000,3.000",
        "0.000,follower 1,4.000,5.000,6.000",
        "0.500,leader,1.000,2.000,3.000",
        "0.500,follower 1,4.000,5.000,6.250",
    ]
    buf.seek(0)
    t2, pos2, names2 = read_trajectories_csv(buf)
    assert names2 == NAMES
    np.testing.assert_array_equal(t2, t)
    np.testing.assert_allclose(pos2, pos, atol=5e-4)
    with pytest.raises(InputError, match="shape"):
        write_trajectories_csv(io.StringIO(), t, pos[:, :1], NAMES)
    with pytest.raises(InputError, match="multiple"):
        read_trajectories_csv(io.StringIO("time_s,uav,x_m,y_m,z_m\n0,a,0,0,0\n0,b,0,0,0\n"
                                          "1,a,0,0,0\n"))


def test_metrics_and_cycles_exact_text():
    buf = io.StringIO()
    write_formation_metrics_csv(buf, [0.0, 1.0], [60.0, 45.5], [0.0, 3.25], [0.0, 0.05])
    assert buf.getvalue().splitlines() == [
        "time_s,min_distance_m,shape_error_m,shape_error_norm",
        "0.000,60.000,0.000,0.0000", "1.000,45.500,3.250,0.0500"]
    buf = io.StringIO()
    write_cycles_csv(buf, [0.0], [0.0021], [[0.75]], [[[1, 2, 3], [4, 5, 6]]],
                     [[False, True]], NAMES)
    rows = list(csv.reader(io.StringIO(buf.getvalue())))
    assert rows[0] == ["cycle", "time_s", "compute_ms", "grey_f1",
                       "goal_leader_x_m", "goal_leader_y_m", "goal_leader_z_m", "held_leader",
                       "goal_follower1_x_m", "goal_follower1_y_m", "goal_follower1_z_m",
                       "held_follower1"]
    assert rows[1] == ["0", "0.000", "2.100", "0.750", "1.000", "2.000", "3.000", "0",
                       "4.000", "5.000", "6.000", "1"]
