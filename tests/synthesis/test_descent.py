"""The descent check against analytic truth: a flat wall, a vertical cylinder, the lean rule."""

import math
from dataclasses import replace

import numpy as np
import pytest

import contourgrasp as cg
from contourgrasp import load_hand
from contourgrasp.errors import HandError, NoFeasibleGrasp, PerceptionError, PlannerError
from contourgrasp.hand import Hand, SampledChain, chain_joints, chain_tip
from contourgrasp.perception import HeightMap
from contourgrasp.synthesis._descent_kernels import map_clearances
from contourgrasp.synthesis.descent import (Descent, _open_hand, body_names, check_candidates, descent_clearance,
                                            descent_feasible, descent_floor, height_base)

CELL = 0.002
CAMERA = 0.7  # camera height above the table: a point at planning depth z is 0.7 - z above it


@pytest.fixture(scope="module")
def hand():
    return load_hand("five-finger-linear")


def scene(height, *, origin=(-0.4, -0.4), shape=(400, 400), in_view=None):
    """A synthetic top-down HeightMap: ``height(x, y)`` at the cells' centres (y rows, x columns)."""
    ny, nx = shape
    x = origin[0] + (np.arange(nx) + 0.5) * CELL
    y = origin[1] + (np.arange(ny) + 0.5) * CELL
    h = np.asarray(height(*np.meshgrid(x, y)), dtype=float) * np.ones(shape)
    return HeightMap(
        heights=h, cell=CELL, origin=np.array(origin, dtype=float), object=h > 0.01, obstacles=np.zeros(shape, bool),
        max_height=float(np.nanmax(h)), in_view=np.ones(shape, bool) if in_view is None else in_view,
        table_normal=np.array([0.0, 0.0, -1.0]), table_offset=CAMERA, camera_xy=np.zeros(2), camera_height=CAMERA,
    )


def finger(hand, name):
    i = [f.name for f in hand.fingers].index(name)
    return i, hand.chains[i]


def lean(chain):
    """(tilt, radius) of an open chain hanging straight (q2 = 0)."""
    assert chain.open_angles[1] == 0.0
    return -chain.open_angles[0], chain.radius


def offset(chain, wall, tip_height):
    """The lean rule: how far outside a wall edge of height ``wall`` the tip must start, m."""
    tilt, r = lean(chain)
    return r / math.cos(tilt) + math.tan(tilt) * (wall - tip_height)


def middle_pose(hand, edge_y, wall, tip_height, clearance):
    """A yaw-0 pose whose middle finger's axis lies on a cell-centre column and whose tip is
    ``offset`` for ``wall + clearance`` outside the edge row ``edge_y`` (+y: the middle finger leans to +y)."""
    _, chain = finger(hand, "middle")
    tip = chain_tip(chain, 0.0)[0]
    x = -tip[0] + 0.5 * CELL  # the axis over the column of centres at x = 0.001
    y = edge_y + offset(chain, wall + clearance, tip_height) - tip[1]
    return np.array([x, y, 0.0])


def circle(r, n=200):
    """(n, 2) float: a circle of radius r about the origin."""
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[r * np.cos(a), r * np.sin(a)]


def ringed_column(r, height, gap, ring_height):
    """A column (the object) of radius r and a ring (an obstacle) from r + gap[0] to r + gap[1] around it."""
    def h(x, y):
        d = np.hypot(x, y)
        return np.where(d <= r, height, np.where((d > r + gap[0]) & (d < r + gap[1]), ring_height, 0.0))

    heights = scene(h)
    return replace(heights, object=heights.heights == height, obstacles=heights.heights == ring_height)


# A rim: a thin wall of height H under the middle finger only, its last row of cell centres at EDGE.
H, TIP, EDGE = 0.04, 0.02, 0.1 + 0.5 * CELL


def rim(x, y):
    return np.where((np.abs(x) < 0.006) & (y < EDGE + 1e-9) & (y > EDGE - 0.01), H, 0.0)


def test_a_finger_1mm_over_a_rim_clears_it_by_1mm_and_2mm_lower_strikes(hand):
    hm = scene(rim)
    names = body_names(hand)
    pose = middle_pose(hand, EDGE, H, TIP, 0.001)
    check = descent_feasible(hand, hm, [pose], TIP)
    assert check.clearance[0, names.index("middle distal")] == pytest.approx(0.001, abs=1e-9)
    assert check.feasible[0] and check.blocking[0] == -1
    lower = descent_feasible(hand, hm, [pose], TIP - 0.002)
    assert lower.clearance[0, names.index("middle distal")] == pytest.approx(-0.001, abs=5e-4)
    assert not lower.feasible[0]
    assert names[lower.blocking[0]] == "middle distal"
    assert "middle distal strikes" in lower.reason(0)
    # 1 mm clear passes a 0 margin but not a 2 mm one
    assert not descent_feasible(hand, hm, [pose], TIP, margin=0.002).feasible[0]


def test_a_vertical_cylinder_rim(hand):
    # A thin can (a bottle's neck) under the middle finger, its rim's apex on the row of centres at EDGE, column x = 0.001
    radius, centre_y = 0.008, EDGE - 0.008
    hm = scene(lambda x, y: np.where(np.hypot(x - 0.5 * CELL, y - centre_y) <= radius + 1e-9, H, 0.0))
    names = body_names(hand)
    for clear, expect_feasible in ((0.001, True), (-0.001, False)):
        check = descent_feasible(hand, hm, [middle_pose(hand, EDGE, H, TIP, clear)], TIP)
        distal = check.clearance[0, names.index("middle distal")]
        assert distal == pytest.approx(clear, abs=1e-9)
        assert check.feasible[0] == expect_feasible
        if not expect_feasible:
            assert names[check.blocking[0]] == "middle distal"


@pytest.mark.parametrize("name, wall", [("middle", 0.03), ("middle", 0.08), ("thumb", 0.05)])
def test_the_lean_rule_r_over_cos_plus_tan_times_wall_height(hand, name, wall):
    """The clearance of the finger's lowest body changes sign where the lean rule says, within a cell."""
    i, chain = finger(hand, name)
    tip = chain_tip(chain, 0.0)[0]
    outward = np.asarray(chain.direction) * -1.0  # open fingers lean away from their flexion direction
    yaw = math.atan2(1.0, 0.0) - math.atan2(outward[1], outward[0])  # turn the lean to +y
    c, s = math.cos(yaw), math.sin(yaw)
    tip_xy = np.array([c * tip[0] - s * tip[1], s * tip[0] + c * tip[1]])
    tilt, _ = lean(chain)
    # this finger's own tip height: the lowest tip is at TIP (the thumb's hangs higher than the others')
    own_tip = TIP + max(chain_tip(ch, 0.0)[0][2] for ch in hand.chains) - tip[2]
    need = offset(chain, wall, own_tip)
    assert (name == "thumb") or need == pytest.approx(0.0095 + 0.33 * (wall - TIP), abs=5e-4)
    hm = scene(lambda x, y: np.where(y < EDGE + 1e-9, wall, 0.0))
    starts = need + np.linspace(-2 * CELL, 2 * CELL, 41)
    poses = np.c_[np.full(len(starts), 0.5 * CELL - tip_xy[0]), EDGE + starts - tip_xy[1], np.full(len(starts), yaw)]
    cols = [3 * i + 1, 3 * i + 2]  # proximal, distal
    clearance = descent_clearance(hand, hm, poses, TIP)[:, cols].min(axis=1)
    assert clearance[0] < 0 < clearance[-1]
    assert np.all(np.diff(clearance) >= -1e-12)
    crossing = float(np.interp(0.0, clearance, starts))
    assert abs(crossing - need) <= CELL
    if name == "middle":  # an axis-aligned finger over a centre column: exact
        assert crossing == pytest.approx(need, abs=1e-4)
        # and the clearance there grows at cos(tilt) / sin(tilt) per m of tip offset
        near = np.abs(starts - need) <= CELL  # while the edge is under the link's side, not its end
        slope = np.polyfit(starts[near], clearance[near], 1)[0]
        assert slope == pytest.approx(1.0 / math.tan(tilt), rel=1e-6)


def test_an_object_lower_than_the_tips_changes_nothing(hand):
    table = scene(lambda x, y: 0.0)
    box = scene(lambda x, y: np.where((np.abs(x) < 0.05) & (np.abs(y - 0.1) < 0.05), 0.005, 0.0))
    rng = np.random.default_rng(3)
    poses = np.c_[rng.uniform(-0.02, 0.02, 50), rng.uniform(-0.02, 0.02, 50), rng.uniform(-np.pi, np.pi, 50)]
    a = descent_clearance(hand, table, poses, 0.02)
    b = descent_feasible(hand, box, poses, 0.02)
    assert b.feasible.all() and (a > 0).all()
    # on a bare table the lowest body is a fingertip's end cap: tip height minus its radius, within a cell
    lowest = a.min(axis=1)
    r = min(ch.radius for ch in hand.chains)
    assert np.all(lowest >= 0.02 - r - 1e-12) and np.all(lowest <= 0.02 - r + 0.15e-3)
    # and below its radius the tip strikes the table itself
    assert not descent_feasible(hand, table, poses, r - 0.001).feasible.any()


def test_unseen_cells_are_bounded_and_out_of_view_blocks(hand):
    names = body_names(hand)
    pose = middle_pose(hand, EDGE, H, TIP, 0.001)

    def tall(x, y):  # the rim, and a tall post far from the hand, so unseen cells get a bound above the tips
        return np.where((np.abs(x + 0.15) < 0.01) & (np.abs(y + 0.05) < 0.01), 0.15, rim(x, y))

    seen = scene(tall)
    assert descent_feasible(hand, seen, [pose], TIP).feasible[0]
    hidden = scene(tall)
    hidden.heights[hidden.centres()[1] > 0.05] = np.nan  # unseen around the hand: no seen cell can have hidden it
    bounded = descent_clearance(hand, hidden, [pose], TIP)
    as_bound = descent_clearance(hand, scene(lambda x, y: hidden.conservative()), [pose], TIP)
    np.testing.assert_array_equal(bounded, as_bound)
    assert bounded[0, names.index("middle distal")] < 0  # not free space: bounded by the post's 0.15 m
    # a cell out of the camera's view under the finger: -inf, refused
    in_view = np.ones(seen.shape, bool)
    in_view[~hidden.seen] = False
    out = scene(tall, in_view=in_view)
    out.heights[~in_view] = np.nan
    check = descent_feasible(hand, out, [pose], TIP)
    assert check.clearance[0, names.index("middle distal")] == -np.inf and not check.feasible[0]
    assert "out of the camera's view" in check.reason(0)
    # off the grid: the same
    far = descent_feasible(hand, seen, [[5.0, 5.0, 0.0]], TIP)
    assert (far.clearance == -np.inf).all()


def test_the_palm_strikes_a_tall_object_beneath_it(hand):
    hm = scene(lambda x, y: np.where((np.abs(x) < 0.01) & (np.abs(y - 0.14) < 0.01), 0.2, 0.0))
    check = descent_feasible(hand, hm, [[0.0, 0.0, 0.0]], TIP)
    assert body_names(hand)[check.blocking[0]] == "palm"
    palm_height = TIP + chain_tip(hand.chains[2], 0.0)[0][2]  # every tip is as deep; palm underside above them
    assert check.clearance[0, -1] == pytest.approx(palm_height - 0.2, abs=1e-9)


def test_a_tilted_palm_strikes_where_its_underside_is_deepest(hand):
    # the palm's underside tilted down toward +x by 0.5 m/m: over a post one cell wide at (x, 0.14) (a column of
    # cell centres) its lowest point is z = 0.5 x deeper than the flat palm's, so the clearance drops by exactly that
    palm = hand.palm
    tilted = replace(hand, palm=replace(palm, depths=tuple(0.5 * x for x, _ in palm.outline)))
    for x in (-0.021, 0.001, 0.031):
        post = scene(lambda gx, gy, x=x: np.where((np.abs(gx - x) < 1e-4) & (np.abs(gy - 0.14) < 0.003), 0.2, 0.0))
        flat = descent_clearance(hand, post, [[0.0, 0.0, 0.0]], TIP)[0, -1]
        lowered = descent_clearance(tilted, post, [[0.0, 0.0, 0.0]], TIP)[0, -1]
        assert lowered - flat == pytest.approx(-0.5 * x, abs=1e-9)


def test_a_hand_of_sampled_chains_descends_as_its_planar_chains(hand):
    sampled = replace(hand, chains=tuple(SampledChain(joints=chain_joints(c, np.linspace(0, 1, 21)), radius=c.radius)
                                         for c in hand.chains))
    wall = scene(lambda x, y: np.where(y > 0.1, 0.12, 0.0))
    rng = np.random.default_rng(3)
    poses = np.c_[rng.uniform(-0.05, 0.05, (50, 2)), rng.uniform(0, 2 * np.pi, 50)]
    np.testing.assert_allclose(descent_clearance(sampled, wall, poses, TIP), descent_clearance(hand, wall, poses, TIP),
                               atol=1e-12)
    assert body_names(sampled) == body_names(hand)


def test_refusing_early_keeps_every_verdict_and_the_feasible_poses_exact(hand):
    wall = scene(lambda x, y: np.where(y > 0.1, 0.12, 0.0))
    rng = np.random.default_rng(5)
    poses = np.c_[rng.uniform(-0.1, 0.1, (200, 2)), rng.uniform(0, 2 * np.pi, 200)]
    exact = descent_feasible(hand, wall, poses, TIP, margin=0.003)
    early = descent_feasible(hand, wall, poses, TIP, margin=0.003, refuse_below=-0.01)
    assert exact.exact and not early.exact
    np.testing.assert_array_equal(early.feasible, exact.feasible)
    assert 20 < exact.feasible.sum() < 180
    np.testing.assert_array_equal(early.clearance[exact.feasible], exact.clearance[exact.feasible])
    refused = exact.clearance.min(axis=1) < -0.01
    assert refused.sum() > 20
    assert (early.clearance.min(axis=1)[refused] < -0.01).all()  # found below, its walk stopped there
    assert (early.clearance[refused] >= exact.clearance[refused]).all()  # upper bounds; bodies not walked +inf
    assert np.isinf(early.clearance[refused]).any()
    with pytest.raises(PlannerError, match="refuse_below"):
        descent_feasible(hand, wall, poses, TIP, refuse_below=np.nan)


def test_a_pose_refused_like_the_one_before_it_walks_that_body_alone(hand):
    # a post under the palm only: two poses alike are both refused by the palm, the last body; the first pose
    # walks every body up to it, the second starts with the palm and stops there
    post = scene(lambda x, y: np.where((np.abs(x) < 0.01) & (np.abs(y - 0.14) < 0.01), 0.2, 0.0))
    check = descent_feasible(hand, post, [[0.0, 0.0, 0.0]] * 2, TIP, refuse_below=-0.01)
    assert not check.feasible.any() and (check.blocking == len(body_names(hand)) - 1).all()
    assert np.isfinite(check.clearance[0]).all()
    assert np.isfinite(check.clearance[1]).tolist() == [False] * (len(body_names(hand)) - 1) + [True]
    assert check.clearance[1, -1] == check.clearance[0, -1]


def test_bad_arguments_are_refused_by_name(hand):
    hm = scene(lambda x, y: 0.0)
    with pytest.raises(HandError, match="no 3-D geometry"):
        descent_clearance(Hand(name="flat", fingers=hand.fingers, min_touching=3), hm, [[0, 0, 0]], 0.02)
    with pytest.raises(PerceptionError, match="heights"):
        descent_clearance(hand, hm.heights, [[0, 0, 0]], 0.02)
    with pytest.raises(PlannerError, match="poses"):
        descent_clearance(hand, hm, [[0, 0]], 0.02)
    with pytest.raises(PlannerError, match="poses"):
        descent_clearance(hand, hm, [[0, np.nan, 0]], 0.02)
    with pytest.raises(PlannerError, match="tip_height"):
        descent_clearance(hand, hm, [[0, 0, 0]], [0.02, 0.03])
    with pytest.raises(PlannerError, match="tip_height"):
        descent_clearance(hand, hm, [[0, 0, 0]], np.inf)
    with pytest.raises(PlannerError, match="margin"):
        descent_feasible(hand, hm, [[0, 0, 0]], 0.02, margin=-1.0)
    assert descent_clearance(hand, hm, np.zeros((0, 3)), 0.02).shape == (0, 3 * len(hand.fingers) + 1)
    # a per-pose tip height is the same as one at a time
    both = descent_clearance(hand, hm, [[0, 0, 0], [0, 0, 1]], [0.01, 0.03])
    np.testing.assert_array_equal(both[1], descent_clearance(hand, hm, [[0, 0, 1]], 0.03)[0])


def test_the_floor_is_the_tip_height_where_the_least_clearance_is_zero(hand):
    heights = scene(lambda x, y: np.where(np.hypot(x, y) < 0.04, 0.08, 0.0))
    poses = np.array([[0.0, 0.0, 0.3], [0.02, -0.01, 2.0], [0.2, 0.2, 1.0]])
    floor = descent_floor(hand, heights, poses)
    at_floor = descent_clearance(hand, heights, poses, floor).min(axis=1)
    np.testing.assert_allclose(at_floor, 0.0, atol=1e-12)
    assert floor[2] == pytest.approx(0.009, abs=1e-4)  # over the bare table: the lowest tips (9 mm) touch it


def test_candidates_are_checked_in_order_and_raised_up_to_the_highest_accepted(hand):
    heights = scene(rim)
    clear = middle_pose(hand, EDGE, H, TIP, 0.002)
    struck = middle_pose(hand, EDGE, H, TIP, -0.005)
    poses = np.array([struck, clear, clear])
    exact = Descent(heights, TIP, TIP, margin=0.001)
    passed, tip, last = check_candidates(hand, exact, poses, [0, 1, 2])
    assert passed.tolist() == [False, True, True] and tip[0] > TIP and tip[1] == TIP
    raised = Descent(heights, TIP, TIP + 0.05, margin=0.001)
    passed, tip, _ = check_candidates(hand, raised, poses, [0])
    assert passed[0] and descent_feasible(hand, heights, poses[:1], tip[:1], margin=0.001).feasible[0]
    np.testing.assert_allclose(descent_clearance(hand, heights, poses[:1], tip[:1]).min(), 0.001, atol=1e-12)
    assert last is not None and not passed[:0].any()


def test_the_search_keeps_the_open_hand_clear_of_a_tall_object(hand):
    """A 12 cm column that the 2-D plan strikes: with the descent check the plan clears it by the margin."""
    from contourgrasp import synthesis

    r = 0.05
    contour = circle(r)
    heights = scene(lambda x, y: np.where(np.hypot(x, y) <= r, 0.12, 0.0))
    options = dict(xy_step=0.01, yaw_step=math.radians(8))
    flat = cg.synthesize(contour, hand, **options)
    assert descent_clearance(hand, heights, [flat.pose], 0.02).min() < 0  # the 2-D plan strikes
    plan = cg.synthesize(contour, hand, descent=Descent(heights, 0.02, 0.08), **options)
    assert plan.descent.feasible[0] and plan.descent.clearance.min() >= plan.descent.margin - 1e-9
    assert 0.02 <= plan.descent.tip_height[0] <= 0.08
    with pytest.raises(NoFeasibleGrasp, match="strike the scene"):
        cg.synthesize(contour, hand, descent=Descent(heights, 0.02, 0.02, margin=0.3), **options)


def test_descent_options_are_checked(hand):
    heights = scene(rim)
    with pytest.raises(PlannerError, match="below tip_height"):
        Descent(heights, 0.05, 0.04)
    with pytest.raises(PerceptionError, match="HeightMap"):
        Descent("map", 0.05, 0.05)
    with pytest.raises(PlannerError, match="descent must be"):
        from contourgrasp import synthesis
        cg.synthesize(np.array([[0, 0], [0.05, 0], [0.05, 0.05]]), hand, descent="yes")
    with pytest.raises(HandError, match="no 3-D geometry"):
        from contourgrasp import synthesis
        cg.synthesize(np.array([[0, 0], [0.05, 0], [0.05, 0.05]]), load_hand("five-finger-curved-thumb"),
                         descent=Descent(heights, 0.05, 0.05))


def test_a_pose_blocked_only_by_a_neighbour_says_so(hand):
    """A 12 cm column ringed by a 15 cm wall 4 cm away: no pose fits, and the message names the neighbour."""
    from contourgrasp import synthesis

    r = 0.05
    contour = circle(r)
    heights = ringed_column(r, 0.05, (0.04, 0.06), 0.15)
    with pytest.raises(NoFeasibleGrasp, match="blocked by a neighbouring object or the bin wall"):
        cg.synthesize(contour, hand, descent=Descent(heights, 0.02, 0.02), xy_step=0.01, yaw_step=math.radians(8))


def test_a_low_ring_the_closing_fingers_would_cross_blocks_every_pose_and_says_so(hand):
    """A 5 cm column ringed 2 cm away by a 15 mm kerb: the open hand descends clear outside the kerb, but every
    finger closing from there runs through it, lower than the tips' balls (11 mm above the table)."""
    from contourgrasp import synthesis

    r = 0.05
    contour = circle(r)
    heights = ringed_column(r, 0.05, (0.02, 0.025), 0.015)
    options = dict(xy_step=0.01, yaw_step=math.radians(8))
    plan = cg.synthesize(contour, hand, descent=Descent(heights, 0.02, 0.02), **options)
    assert plan.descent.feasible[0]  # without the closing check the hand would close through the kerb
    with pytest.raises(NoFeasibleGrasp, match="blocked by a neighbouring object or the bin wall: .* would run a "
                                              "finger into a neighbouring object or the bin wall while the hand closes"):
        cg.synthesize(contour, hand, descent=Descent(heights, 0.02, 0.02, closing=True), **options)


def test_a_yes_no_walk_is_exact_below_its_threshold_and_no_lower_above_it(hand):
    """``only_below`` skips cells that cannot bring a gap below it: the closing sweep's speed-up changes no answer."""
    rng = np.random.default_rng(5)
    bumps = np.c_[rng.uniform(-0.06, 0.06, (6, 2)), rng.uniform(0.0, 0.12, 6)]
    heights = scene(lambda x, y: sum(np.where(np.hypot(x - a, y - b) < 0.02, h, 0.0) for a, b, h in bumps))
    poses = np.c_[rng.uniform(-0.1, 0.1, (200, 2)), rng.uniform(-np.pi, np.pi, 200)]
    bodies = _open_hand(hand)
    base = height_base(hand, poses, 0.02, np.asarray(heights.table_normal))
    full = map_clearances(heights, hand, poses, base, bodies.capsules, bodies.radii)
    for threshold in (0.0, 0.03):
        fast = map_clearances(heights, hand, poses, base, bodies.capsules, bodies.radii,
                              only_below=np.full(len(poses), threshold))
        low = full < threshold
        assert 0 < low.sum() < low.size
        assert np.array_equal(fast[low], full[low]) and (fast[~low] >= threshold).all()
