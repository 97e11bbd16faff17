"""Exact values of the formation shapes and of eqs 6.1 / 6.2."""

import numpy as np
import pytest

from fm2uav import InputError
from fm2uav.missions.formation import formation_shape, slot_offsets, slot_positions


def test_triangle_is_the_thesis_triangle():
    s = formation_shape("triangle", 2)
    np.testing.assert_array_equal(s.offsets, [[2, 2], [2, -2]])
    np.testing.assert_array_equal(s.column, [1, 2])


def test_eq_6_1_and_6_2():
    s = formation_shape()
    # B = 1: nominal; B = 0: single file 2·dist apart; B = 0.5: d1 = 2(2 - B), d2 = ±2B
    np.testing.assert_allclose(slot_offsets(s, [1.0, 1.0]), [[2, 2], [2, -2]])
    np.testing.assert_allclose(slot_offsets(s, [0.0, 0.0]), [[2, 0], [4, 0]])
    np.testing.assert_allclose(slot_offsets(s, [0.5, 0.5]), [[2, 1], [3, -1]])
    np.testing.assert_allclose(slot_offsets(s, [0.25, 1.0]), [[2, 0.5], [2, -2]])


def test_v_and_line_shapes():
    np.testing.assert_array_equal(formation_shape("v", 4).offsets,
                                  [[2, 2], [2, -2], [4, 4], [4, -4]])
    np.testing.assert_array_equal(formation_shape("line", 3).offsets, [[2, 0], [4, 0], [6, 0]])
    np.testing.assert_array_equal(formation_shape("triangle", 5).offsets,
                                  [[2, 2], [2, -2], [4, 4], [4, 0], [4, -4]])
    # a line does not deform
    s = formation_shape("line", 3)
    np.testing.assert_allclose(slot_offsets(s, [0.3, 0.6, 0.0]), s.offsets)


def test_slot_positions_in_the_leader_frame():
    offs = np.array([[2.0, 2.0], [2.0, -2.0]])
    p = slot_positions(np.array([100.0, 50.0]), np.array([1.0, 0.0]), offs, 10.0)
    np.testing.assert_allclose(p, [[80, 70], [80, 30]])
    # heading +y: "left" is -x
    p = slot_positions(np.array([0.0, 0.0]), np.array([0.0, 1.0]), offs, 10.0)
    np.testing.assert_allclose(p, [[-20, -20], [20, -20]], atol=1e-12)


def test_deformed_triangle_goals_never_collapse():
    """For every pair of grey levels the partial goals stay >= sqrt(2)·dist apart."""
    s = formation_shape()
    B = np.linspace(0, 1, 41)
    b1, b2 = np.meshgrid(B, B, indexing="ij")
    offs = slot_offsets(s, np.stack([b1.ravel(), b2.ravel()], axis=1))  # (m, 2, 2)
    between = np.linalg.norm(offs[:, 0] - offs[:, 1], axis=1)
    to_leader = np.linalg.norm(offs, axis=2)
    assert between.min() == pytest.approx(np.sqrt(2.0))
    assert to_leader.min() == pytest.approx(2.0)


@pytest.mark.parametrize("args", [("square", 2), ("triangle", 0), ("v", 1.5)])
def test_bad_shapes(args):
    with pytest.raises(InputError):
        formation_shape(*args)
