"""Pairing colour and depth images by stamp (pure Python, no ROS)."""

from contourgrasp.ros.pairing import STAMP_JUMP, Pairer, nearest


def test_nearest_takes_the_closest_stamp_within_the_tolerance_and_the_later_on_a_tie():
    assert nearest([1.0, 1.03, 1.1], 1.02, 0.02) == 1
    assert nearest([1.0, 1.5], 1.25, 0.25) == 1
    assert nearest([1.0], 1.021, 0.02) is None
    assert nearest([], 1.0, 0.02) is None


def test_a_message_pairs_once_with_the_nearest_partner():
    p = Pairer(tolerance=0.02)
    assert p.add_colour(1.0, "c1") is None
    assert p.add_depth(1.5, "d-late") is None
    assert p.add_depth(1.005, "d1") == ("c1", "d1")
    assert p.add_depth(1.01, "d1b") is None  # c1 is taken
    assert p.newest == ("c1", "d1") and p.newest_stamp == 1.0
    assert p.add_colour(1.49, "c2") == ("c2", "d-late")
    assert p.newest_stamp == 1.49


def test_an_older_pair_completed_late_does_not_replace_the_newest():
    p = Pairer(tolerance=0.02, keep=3)
    p.add_colour(1.0, "c1")
    p.add_colour(2.0, "c2")
    assert p.add_depth(2.0, "d2") == ("c2", "d2")
    assert p.add_depth(1.0, "d1") == ("c1", "d1")
    assert p.newest == ("c2", "d2")


def test_only_the_last_unpaired_messages_wait():
    p = Pairer(tolerance=0.02, keep=2)
    for t in (1.0, 2.0, 3.0):
        p.add_colour(t, f"c{t:g}")
    assert p.add_depth(1.0, "d1") is None
    assert p.add_depth(2.0, "d2") == ("c2", "d2")


def test_a_clock_jump_back_is_taken_and_told_not_a_lock():
    """One frame stamped far ahead (a driver's clock reset, sim time against wall time) must not freeze the newest
    pair: every later frame would be passed over and ~/plan would answer the stale plan."""
    p = Pairer(tolerance=0.02)
    p.add_colour(1e9, "ahead")
    assert p.add_depth(1e9, "d-ahead") == ("ahead", "d-ahead") and p.jumped is None
    p.add_colour(10.0, "c10")
    assert p.add_depth(10.0, "d10") == ("c10", "d10")
    assert p.newest == ("c10", "d10") and p.jumped == 1e9 - 10.0
    p.add_colour(10.1, "c10.1")
    p.add_depth(10.1, "d10.1")
    assert p.newest == ("c10.1", "d10.1") and p.jumped is None


def test_a_pair_completed_out_of_order_within_the_jump_keeps_the_newer():
    p = Pairer(tolerance=0.02, keep=3)
    p.add_colour(10.0, "c1")
    p.add_colour(10.0 + STAMP_JUMP, "c2")
    p.add_depth(10.0 + STAMP_JUMP, "d2")
    p.add_depth(10.0, "d1")
    assert p.newest == ("c2", "d2") and p.jumped is None
