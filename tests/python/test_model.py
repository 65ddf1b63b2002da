"""The model from Python: Hose.along_route, grab, step, and points as a NumPy view."""
import math

import numpy as np
import pytest

import chaintube

ROUTE = [(0.0, 0.0, 0.0), (1.0, 0.0, 0.0), (1.0, 0.5, 0.0)]


def make_hose(**spec):
    return chaintube.Hose.along_route(ROUTE, chaintube.HoseSpec(segment_count=20, **spec))


def test_points_is_a_read_only_view_that_follows_the_hose_after_a_grab():
    hose = make_hose()
    view = hose.points
    assert view.shape == (21, 3)
    assert not view.flags.writeable and not view.flags.owndata
    address = view.__array_interface__["data"][0]
    before = view.copy()

    middle = hose.point_count // 2
    target = before[middle] + np.array([0.0, 0.2, 0.1])
    result = hose.grab(middle, target)
    assert result.status == chaintube.Status.Ok
    assert result.moved_points > 0

    # The view held from before the grab shows the new shape: the same memory, no copy.
    assert hose.points.__array_interface__["data"][0] == address
    assert np.shares_memory(view, hose.points)
    np.testing.assert_allclose(view[middle], target, atol=1e-9)
    assert not np.allclose(view, before)
    each = np.array([hose.point(i) for i in range(hose.point_count)])
    np.testing.assert_array_equal(view, each)
    with pytest.raises(ValueError):
        view[0, 0] = 1.0


def test_the_view_stays_valid_after_the_hose_object_is_dropped():
    view = make_hose().points  # the array keeps the hose alive (its base)
    assert view.base is not None
    assert np.isfinite(view).all() and view.shape == (21, 3)


def test_a_rejected_grab_changes_nothing():
    hose = make_hose()
    first = hose.attach(0, 0)
    assert first > 0 and hose.is_fixed(0)
    before = hose.points.copy()
    assert hose.grab(0, (5.0, 5.0, 5.0)).status == chaintube.Status.InvalidInput
    assert hose.grab(99, (0.0, 0.0, 0.0)).status == chaintube.Status.InvalidInput
    assert hose.grab(3, (math.nan, 0.0, 0.0)).status == chaintube.Status.InvalidInput
    np.testing.assert_array_equal(hose.points, before)


def test_every_segment_keeps_its_stretch_band_after_a_grab():
    hose = make_hose(material=chaintube.Material(0.05, min_bend_radius=0.1))
    hose.attach(0, 1)
    hose.grab(hose.point_count - 1, (0.2, 0.9, 0.4))
    lengths = np.linalg.norm(np.diff(hose.points, axis=0), axis=1)
    assert (lengths <= hose.rest_lengths * 1.05 + 1e-9).all()
    assert (lengths >= hose.rest_lengths * 0.95 - 1e-9).all()
    assert hose.measure_violation().length_violation <= 1e-9


def test_step_lets_a_hose_held_at_one_end_fall_and_the_view_shows_it():
    hose = make_hose(gravity=True)
    hose.attach(0, 1)
    view = hose.points
    lowest = view[:, 1].min()
    for _ in range(30):
        result = hose.step()
        assert result.status in (chaintube.Status.Ok, chaintube.Status.Clamped)
    assert view[:, 1].min() < lowest - 0.01
    np.testing.assert_allclose(view[0], ROUTE[0], atol=1e-12)  # the fixed end stays


def test_step_takes_the_frame_time_and_refuses_a_bad_one_changing_nothing():
    hose = make_hose(gravity=True)
    hose.attach(0, 1)
    before = hose.points.copy()
    for seconds in (0.0, -0.01, 0.2, math.nan, math.inf):
        assert hose.step(seconds).status == chaintube.Status.InvalidInput
        np.testing.assert_array_equal(hose.points, before)
    for _ in range(20):
        result = hose.step(1.0 / 45.0)
        assert result.status in (chaintube.Status.Ok, chaintube.Status.Clamped)
    assert hose.points[:, 1].min() < before[:, 1].min() - 0.01
    assert hose.measure_violation().length_violation <= 1e-9


def test_a_route_with_one_point_raises_invalid_argument_naming_the_route():
    with pytest.raises(chaintube.InvalidArgument) as raised:
        chaintube.Hose.along_route([(0.0, 0.0, 0.0)])
    assert "route" in str(raised.value).lower()
