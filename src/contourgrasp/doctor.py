"""A first look at a user's frame: what perception sees in it and what looks wrong (``contourgrasp doctor``).

Users of every grasp planner ask the same first questions of their own camera: are the depth's units
right, do the intrinsics belong to this image size, are colour and depth registered, how much depth is
missing, is the table found and how tilted is it, which objects are seen and which would be planned
on. :func:`diagnose` answers them in a few lines, each a :class:`Finding` with its verdict, and tries
the plan itself so that the last line says whether ``contourgrasp plan`` would plan on this frame.

The checks and their thresholds (:mod:`contourgrasp.tolerances` where shared with perception):

* **depth**: the median valid reading; readings outside the sensor range that perception uses
  (``SENSOR_RANGE``) are counted as ignored; missing readings (0, NaN) as a share of the image,
  and the share of them beside a depth edge (within 2 px of a jump of more than 2 cm between valid
  neighbours: projector shadows, flying-pixel filters) -- those are the sensor's, not the scene's.
* **intrinsics**: the field of view the focal lengths give on this image size; below
  ``DOCTOR_MIN_FOV`` or above ``DOCTOR_MAX_FOV`` degrees they are probably another resolution's. The
  principal point more than ``DOCTOR_CENTRE_SHARE`` of the image size from its centre is flagged too.
* **colour**: its size against the depth's (the same, the same view scaled, or mapped by the colour
  intrinsics); the colour-depth offset on the target (:func:`contourgrasp.perception.colour_offset`),
  flagged above ``DOCTOR_MAX_OFFSET_PX``.
* **support**: the plane the objects stand on, its tilt and distance, and how it was chosen.
* **objects**: the candidates standing on it, how many are wholly in view and narrower than the hand.
* **plan**: :func:`contourgrasp.pipeline.plan_frame` with the hand and options given: planned, or the
  reason it gives.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import cv2
import numpy as np

from . import perception
from . import tolerances as tol
from .errors import InputError, NoFeasibleGrasp
from .hand import Hand
from .perception import Intrinsics
from .pipeline import ImageGraspPlan, PlanOptions, find_objects, plan_frame

#: Verdicts of a finding, in order of gravity.
VERDICTS = ("ok", "note", "warning")


@dataclass(frozen=True)
class Finding:
    """One line of a diagnosis: what was looked at, what was found, and whether it looks wrong.

    Attributes
    ----------
    topic : str
        ``depth``, ``intrinsics``, ``colour``, ``support``, ``objects``, ``target`` or ``plan``.
    text : str
        What was found, one line.
    verdict : {"ok", "note", "warning"}
    """

    topic: str
    text: str
    verdict: str = "ok"


@dataclass(frozen=True, eq=False)
class Diagnosis:
    """What :func:`diagnose` found in a frame.

    Attributes
    ----------
    findings : tuple of Finding
    support : Support or None
        None when no support plane was found.
    result : ImageGraspPlan or None
        The plan, when one was found.
    missing : (H, W) bool
        The depth image's missing readings (0, NaN or outside the sensor range).
    edge_missing : (H, W) bool
        Those of them beside a depth edge.
    rgb : (H, W, 3) uint8 or None
        The colour on the depth image's grid.
    """

    findings: tuple[Finding, ...]
    support: perception.Support | None
    result: ImageGraspPlan | None
    missing: np.ndarray
    edge_missing: np.ndarray
    rgb: np.ndarray | None

    @property
    def warnings(self) -> tuple[Finding, ...]:
        """The findings that look wrong."""
        return tuple(f for f in self.findings if f.verdict == "warning")

    def lines(self) -> list[str]:
        """The findings as text, one line each: ``topic  text`` (a warning's text after ``!``)."""
        width = max(len(f.topic) for f in self.findings)
        return [f"{f.topic:{width}s}  {'! ' if f.verdict == 'warning' else ''}{f.text}" for f in self.findings]


def diagnose(rgb, depth, intrinsics: Intrinsics, hand: Hand, *, colour_intrinsics: Intrinsics | None = None,
             options: PlanOptions = PlanOptions()) -> Diagnosis:
    """Look at one frame as :func:`contourgrasp.pipeline.plan_frame` would, and say what looks wrong.

    Parameters
    ----------
    rgb : (H', W', 3) or (H', W') uint8, or None
    depth : (H, W) float
        Meters, 0 or NaN where missing.
    intrinsics : Intrinsics
        Of the depth image.
    hand : Hand
        The hand the plan is tried with.
    colour_intrinsics : Intrinsics, optional
        The colour camera's, for a colour image of another aspect than the depth's.
    options : PlanOptions

    Returns
    -------
    Diagnosis

    Raises
    ------
    PerceptionError
        Depth or intrinsics that cannot be used at all (no valid reading, another size than the image).
    """
    perception.camera.check_intrinsics(intrinsics)
    d = perception.as_depth(depth)
    intrinsics.check_shape(d.shape, "depth image")
    findings = [_depth_finding(d, intrinsics)]
    missing = ~perception.valid_depth(d)
    edge_missing = missing & near_depth_edges(d, missing)
    findings.append(_missing_finding(missing, edge_missing))
    findings.append(_intrinsics_finding(intrinsics))
    on_depth = None
    if rgb is not None:
        on_depth = perception.colour_on_depth(rgb, d.shape, intrinsics=None if colour_intrinsics is None else intrinsics,
                                              colour_intrinsics=colour_intrinsics)
        findings.append(_colour_finding(np.shape(rgb), d.shape, colour_intrinsics is not None))
    support = _support(on_depth, d, intrinsics, findings)
    result = None
    if support is not None:
        findings.append(_objects_finding(support, hand))
        result = _plan(on_depth, d, intrinsics, hand, options, findings)
        if result is not None and on_depth is not None:
            findings.append(_offset_finding(on_depth, d, result.segmentation.mask))
    return Diagnosis(tuple(findings), support, result, missing, edge_missing, on_depth)


def _depth_finding(depth: np.ndarray, intrinsics: Intrinsics) -> Finding:
    finite = depth[np.isfinite(depth) & (depth > 0)]
    if finite.size == 0:
        return Finding("depth", "no reading at all (every pixel 0 or NaN)", "warning")
    median = float(np.median(finite))
    lo, hi = tol.SENSOR_RANGE
    outside = float(np.mean((finite < lo) | (finite > hi)))
    text = f"{intrinsics.width}x{intrinsics.height}, median reading {median:.3f} m"
    if not tol.MIN_PLAUSIBLE_DEPTH <= median <= tol.MAX_PLAUSIBLE_DEPTH:
        return Finding("depth", f"{text}: not metres (millimetres? give the depth scale, e.g. --depth-scale 0.001)",
                       "warning")
    if outside > 0:
        text += f"; {100 * outside:.0f} % of the readings lie outside {lo:g}-{hi:g} m and are ignored"
    return Finding("depth", text, "warning" if outside > 0.5 else "ok")


def near_depth_edges(depth: np.ndarray, missing: np.ndarray) -> np.ndarray:
    """(H, W) bool: the pixels within ``DOCTOR_EDGE_PX`` of a place where the valid readings (not ``missing``) of
    a 9 x 9 window differ by more than ``DOCTOR_EDGE_STEP``: beside a depth edge, where sensors drop readings
    (also ``benchmarks/sensor_statistics.py``'s edge dropout)."""
    window = np.ones((9, 9), np.uint8)
    high = cv2.dilate(np.where(missing, 0.0, depth).astype(np.float32), window)
    low = -cv2.dilate(np.where(missing, -np.inf, -depth).astype(np.float32), window)
    step = (high - low) > tol.DOCTOR_EDGE_STEP
    return cv2.dilate(step.astype(np.uint8), np.ones((2 * tol.DOCTOR_EDGE_PX + 1,) * 2, np.uint8)) > 0


def _missing_finding(missing: np.ndarray, edge_missing: np.ndarray) -> Finding:
    share = float(missing.mean())
    text = f"{100 * share:.0f} % of the depth missing"
    if share == 0:
        return Finding("missing", text + " (a pre-filtered or rendered depth?)", "note")
    text += f", {100 * edge_missing.sum() / missing.sum():.0f} % of it beside depth edges (shadows, flying pixels)"
    return Finding("missing", text, "warning" if share > tol.DOCTOR_MAX_MISSING else "ok")


def _intrinsics_finding(k: Intrinsics) -> Finding:
    fov = (math.degrees(2 * math.atan(k.width / (2 * k.fx))), math.degrees(2 * math.atan(k.height / (2 * k.fy))))
    off = (abs(k.cx - (k.width - 1) / 2) / k.width, abs(k.cy - (k.height - 1) / 2) / k.height)
    text = (f"fx {k.fx:.1f} fy {k.fy:.1f} cx {k.cx:.1f} cy {k.cy:.1f}: a field of view of {fov[0]:.0f} x {fov[1]:.0f} deg"
            f" on {k.width}x{k.height}")
    low, high = tol.DOCTOR_FOV_DEG
    if not (low <= fov[0] <= high and low <= fov[1] <= high):
        return Finding("intrinsics", f"{text}: unlike a depth camera's ({low:g}-{high:g} deg): intrinsics of another "
                                     "resolution? (scale fx, fy, cx, cy with the image)", "warning")
    if max(off) > tol.DOCTOR_CENTRE_SHARE:
        return Finding("intrinsics", f"{text}; the principal point lies {100 * max(off):.0f} % of the image from its "
                                     "centre (intrinsics of another resolution, or of a cropped image?)", "warning")
    if abs(k.fx - k.fy) > 0.05 * k.fx:
        return Finding("intrinsics", f"{text}; fx and fy differ by {100 * abs(k.fx - k.fy) / k.fx:.0f} % (pixels are "
                                     "square on depth cameras)", "warning")
    return Finding("intrinsics", text)


def _colour_finding(colour_shape, depth_shape, mapped: bool) -> Finding:
    h, w = colour_shape[:2]
    if (h, w) == tuple(depth_shape[:2]):
        return Finding("colour", f"{w}x{h}, the depth's size (taken as registered to it)")
    how = "mapped through the colour intrinsics" if mapped else f"the same view at {w / depth_shape[1]:.2g}x"
    return Finding("colour", f"{w}x{h}: {how}, resampled onto the depth's grid", "note")


def _support(rgb, depth, intrinsics, findings) -> perception.Support | None:
    try:
        support = find_objects(depth, intrinsics, rgb=rgb)
    except perception.SegmentationError as err:
        findings.append(Finding("support", f"no support plane: {err}", "warning"))
        return None
    plane = support.plane
    text = (f"tilted {math.degrees(plane.tilt):.1f} deg, {plane.offset:.3f} m from the camera, "
            f"{int(plane.inliers.sum())} px on it; {support.reason}")
    verdict = "note" if plane.tilt > tol.TILT_WARN else "ok"
    if verdict == "note":
        text += " (an oblique view: the far side of the objects is hidden)"
    findings.append(Finding("support", text, verdict))
    return support


def _objects_finding(support: perception.Support, hand: Hand) -> Finding:
    candidates = support.candidates
    inner = [c for c in candidates if c.in_view]
    fits = [c for c in inner if max(c.extent) <= perception.hand_opening(hand)]
    text = (f"{len(candidates)} standing on it: {len(inner)} wholly in view, {len(fits)} of them narrower than "
            f"{hand.name}'s opening ({1000 * perception.hand_opening(hand):.0f} mm)")
    touching = sum(c.touching for c in candidates)
    if touching:
        text += f"; {touching} of them split from objects they touch (colour and surface change where they meet)"
    return Finding("objects", text, "warning" if not inner else "ok")


def _plan(rgb, depth, intrinsics, hand, options, findings) -> ImageGraspPlan | None:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            result = plan_frame(rgb, depth, intrinsics, hand, options)
        except NoFeasibleGrasp as err:
            findings.append(Finding("plan", f"no feasible grasp: {err.reason}", "warning"))
            return None
        except InputError as err:
            findings.append(Finding("plan", f"not planned: {err}", "warning"))
            return None
    target = result.target
    label = "the user's mask" if target is None else f"candidate {target.label} ({target.area_px} px)"
    findings.append(Finding("target", f"{label}: {result.target_reason}"))
    x, y, yaw = result.plan.pose
    findings.append(Finding("plan", f"planned: grasp at ({x:.3f}, {y:.3f}) m, yaw {math.degrees(yaw):.0f} deg, "
                                    f"{sum(not f.missed for f in result.plan.fingers)}/{len(result.plan.fingers)} "
                                    f"fingers touch"))
    return result


def _offset_finding(rgb, depth, mask) -> Finding:
    try:
        dx, dy = perception.colour_offset(rgb, depth, mask)
    except InputError as err:
        return Finding("registration", f"colour-depth offset not measured: {err}", "note")
    text = f"colour lies ({dx:+d}, {dy:+d}) px from the depth on the target"
    if max(abs(dx), abs(dy)) > tol.DOCTOR_MAX_OFFSET_PX:
        return Finding("registration", f"{text}: not registered? (register them, or plan with --colour-offset "
                                       f"{dx},{dy})", "warning")
    return Finding("registration", text)
