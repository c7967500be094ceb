"""Pairing colour and depth images by stamp (pure Python, no ROS)."""

from contourgrasp.ros.pairing import Pairer, nearest


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
