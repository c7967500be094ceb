"""The depth sensors of the renderer (contourgrasp.sim.render): presets, shadows, dropouts, flying pixels."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.ndimage import maximum_filter, minimum_filter

from contourgrasp.errors import SimulationError
from contourgrasp.sim import SENSORS, Sensor, Workspace, build_scene, render
from contourgrasp.sim.objects import ObjectSpec, Part
from contourgrasp.sim.scene import SR300

HEIGHT, RADIUS, CAMERA_HEIGHT = 0.10, 0.04, 0.65


def can(rgba=(0.6, 0.6, 0.6, 1.0)):
    """A 10 cm tall, 8 cm wide cylinder standing under the camera."""
    spec = ObjectSpec("can", (Part("cylinder", (RADIUS, HEIGHT / 2), pos=(0.0, 0.0, HEIGHT / 2)),), mass=0.3,
                      friction_hand=0.6, friction_table=0.4, rgba=rgba)
    return build_scene(spec, seed=0, workspace=Workspace(0.0, 0.0))


@pytest.fixture(scope="module")
def scene():
    return can()


def test_basic_reads_as_the_benchs_camera_did_before_the_presets(scene):
    # Gaussian noise growing with depth squared, then half the edge pixels dropped: drawn in that order, seed for seed.
    _, exact = render(scene, sensor="ideal")
    _, basic = render(scene, sensor="basic", seed=7)
    rng = np.random.default_rng([7, 1])
    d = exact.astype(np.float64)
    noisy = d + rng.normal(0.0, 1.0, d.shape) * 0.004 * d**2
    edge = maximum_filter(d, size=3) - minimum_filter(d, size=3) > 0.01
    dropped = edge & (rng.random(d.shape) < 0.5)
    want = np.where(dropped | (d == 0), 0.0, noisy)
    np.testing.assert_array_equal(basic == 0, want == 0)
    np.testing.assert_allclose(basic, want, atol=1e-6)  # the picture is float32 of the float64 depth


def test_ideal_is_exact_depth_and_true_and_false_name_basic_and_ideal(scene):
    np.testing.assert_array_equal(render(scene, sensor="ideal")[1], render(scene, sensor=False)[1])
    np.testing.assert_array_equal(render(scene, sensor="basic", seed=3)[1], render(scene, sensor=True, seed=3)[1])
    assert SENSORS["ideal"].ideal and not any(s.ideal for name, s in SENSORS.items() if name != "ideal")


def test_a_projector_beside_the_camera_shadows_the_far_side_of_a_raised_edge(scene):
    # A projector 5 cm along +x: the table just beyond the can's -x edge is lit by no ray that passes the can's top.
    # Seen from the camera, the band runs from where the top hides the table (x = -r H / (H - h)) to where the
    # projector's ray over the top's edge lands (x = b - (b + r) H / (H - h)): 9.1 mm, 6.6 px at 0.65 m.
    _, exact = render(scene, sensor="ideal")
    _, shadowed = render(scene, sensor=Sensor("projector", shadow_baseline=0.05))
    missing = (shadowed == 0) & (exact > 0)
    row = int(round(SR300.cy))
    ratio = CAMERA_HEIGHT / (CAMERA_HEIGHT - HEIGHT)
    near, far = -RADIUS * ratio, 0.05 - (0.05 + RADIUS) * ratio
    expected = (near - far) * SR300.fx / CAMERA_HEIGHT
    left, right = missing[row, : int(SR300.cx)], missing[row, int(SR300.cx):]
    assert not right.any()
    assert left.sum() == pytest.approx(expected, abs=1.5)
    u = np.flatnonzero(left)
    assert u.max() - u.min() + 1 == left.sum()  # one band, beside the can
    assert u.min() == pytest.approx(SR300.cx + far * SR300.fx / CAMERA_HEIGHT, abs=1.5)


def test_dark_surfaces_drop_out_and_light_ones_do_not():
    dark, light = can(rgba=(0.1, 0.1, 0.12, 1.0)), can()
    sensor = Sensor("dark", dark_dropout=0.5)
    for scene, share in ((dark, 0.5), (light, 0.0)):
        _, exact = render(scene, sensor="ideal")
        _, depth = render(scene, sensor=sensor, seed=1)
        top = exact < CAMERA_HEIGHT - HEIGHT + 0.005
        assert ((depth == 0) & top).sum() / top.sum() == pytest.approx(share, abs=0.05)


def test_flying_pixels_lie_between_an_edges_two_sides_and_speckle_covers_its_share(scene):
    _, exact = render(scene, sensor="ideal")
    _, depth = render(scene, sensor=Sensor("tof-like", flying=1.0, speckle=0.02), seed=2)
    near = minimum_filter(np.where(exact > 0, exact, np.inf), size=3)
    far = maximum_filter(exact, size=3)
    edge = far - near > 0.01
    read = edge & (depth > 0)
    assert read.sum() > 100 and np.all((depth[read] >= near[read] - 1e-6) & (depth[read] <= far[read] + 1e-6))
    assert np.abs(depth[read] - exact[read]).max() > 0.05  # mixed: tens of millimetres off either side
    flat = ~maximum_filter(edge, size=5) & (exact > 0)
    assert (depth[flat] == 0).mean() == pytest.approx(0.02, abs=0.01)


def test_an_unknown_sensor_is_refused_naming_the_presets(scene):
    with pytest.raises(SimulationError, match="unknown sensor 'kinect': choose one of ideal, basic, structured-light"):
        render(scene, sensor="kinect")
