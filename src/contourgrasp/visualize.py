"""Figures: the planned grasp (thesis Fig 4.8-4.10) and EFD harmonics (Fig 4.5).

Figures are drawn in the image plane with y pointing down, as the camera sees
them. Functions return matplotlib ``Figure`` objects built without pyplot, so
nothing here touches global plotting state; save them with ``fig.savefig``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import matplotlib
import numpy as np
from matplotlib.collections import LineCollection
from matplotlib.figure import Figure
from mpl_toolkits.axes_grid1.anchored_artists import AnchoredSizeBar

from .contour import clean_polygon, efd
from .hand import chain_capsules, chain_plane, to_image
from .pipeline import plan_to_camera
from .synthesis import GraspPlan

CONVEX_COLOUR = "0.25"
CONCAVE_COLOUR = "tab:blue"
#: Line width (points) of a finger's links in :func:`draw_side_view`.
SIDE_VIEW_LINK_WIDTH = 4.0
FINGER_COLOURS = ("tab:red", "tab:orange", "tab:green", "tab:purple", "tab:brown", "tab:pink", "tab:olive")


def draw_efd(ax, model: efd.EFD, *, curvature: str = "paper", samples: int = 720, linewidth: float = 2.0):
    """Draw the EFD curve on ``ax`` with concave stretches coloured."""
    t, points = efd.sample(model, samples)
    concave = efd.concave(model, t, curvature)
    closed = np.vstack([points, points[:1]])
    segments = np.stack([closed[:-1], closed[1:]], axis=1)
    colours = np.where(concave, CONCAVE_COLOUR, CONVEX_COLOUR)
    ax.add_collection(LineCollection(segments, colors=colours, linewidths=linewidth))


def draw_plan(ax, plan: GraspPlan) -> None:
    """Draw a plan on ``ax``: polygon, EFD contour, finger trajectories, starts, virtual starts, grasp points."""
    ax.plot(*np.vstack([plan.contour, plan.contour[:1]]).T, color="0.7", lw=1, label="input contour")
    draw_efd(ax, plan.efd, curvature=plan.curvature_mode)
    ax.plot([], [], color=CONVEX_COLOUR, lw=2, label="EFD convex")
    ax.plot([], [], color=CONCAVE_COLOUR, lw=2, label="EFD concave")
    pose = plan.pose
    for i, (finger, contact) in enumerate(zip(plan.hand.fingers, plan.fingers)):
        colour = FINGER_COLOURS[i % len(FINGER_COLOURS)]
        reach = finger.travel if contact.missed else contact.lam
        travelled = to_image(finger.points(np.linspace(0, reach, 50)), pose)
        rest = to_image(finger.points(np.linspace(reach, finger.travel, 20)), pose)
        ax.plot(*travelled.T, color=colour, lw=1.8, ls="--" if contact.missed else "-")
        ax.plot(*rest.T, color=colour, lw=1, alpha=0.3)
        ax.plot(*contact.start, "o", color=colour, ms=6, mfc="white")
        ax.plot(*contact.virtual_start, "x", color=colour, ms=6)
        marker = "X" if contact.missed else "*"
        ax.plot(*contact.grasp_point, marker, color=colour, ms=13, mec="black", mew=0.6)
        label = finger.name + (" (missed)" if contact.missed else "")
        ax.annotate(label, contact.start, textcoords="offset points", xytext=(5, 5), color=colour, fontsize=9)
    ax.plot(*pose[:2], "s", color="black", ms=6)
    heading = to_image(np.array([[0.0, 0.0], [0.03, 0.0]]), pose)
    ax.annotate("", heading[1], heading[0], arrowprops={"arrowstyle": "->", "color": "black"})
    ax.plot([], [], "o", color="0.3", mfc="white", label="start")
    ax.plot([], [], "x", color="0.3", label="virtual start")
    ax.plot([], [], "*", color="0.3", ms=10, label="grasp point")
    ax.plot([], [], "s", color="black", label="hand pose (x, y, yaw)")


def _finish_axes(ax, scale: float = 0.05) -> None:
    ax.set_aspect("equal")
    ax.autoscale_view()
    if not ax.yaxis_inverted():
        ax.invert_yaxis()
    ax.set_xlabel("x [m] (image right)")
    ax.set_ylabel("y [m] (image down)")
    ax.add_artist(AnchoredSizeBar(ax.transData, scale, _length_label(scale), "lower right", frameon=False,
                                  size_vertical=scale / 40))
    ax.grid(alpha=0.3)


def _scale_bar(extent: float) -> float:
    """The longest of 1, 2, 5 x 10^k m within a quarter of ``extent``: 2 cm for the thesis's objects."""
    decade = 10.0 ** math.floor(math.log10(extent / 4))
    return max(step * decade for step in (1, 2, 5) if step * decade <= extent / 4)


def _length_label(length: float) -> str:
    """``length`` m in the unit that reads best: "2 cm", "50 µm", "20 m"."""
    for unit, size in (("m", 1.0), ("cm", 1e-2), ("mm", 1e-3), ("µm", 1e-6)):
        if length >= size:
            return f"{round(length / size, 9):g} {unit}"
    return f"{length:.3g} m"


def plan_figure(plan: GraspPlan) -> Figure:
    """The thesis's Figure 4.8-4.10 picture of a plan, with its cost in the title."""
    fig = Figure(figsize=(9.5, 7.0), layout="constrained")
    ax = fig.add_subplot()
    draw_plan(ax, plan)
    _finish_axes(ax)
    x, y, yaw = plan.pose
    c = plan.cost
    ax.set_title(
        f"{plan.hand.name}: pose x={x:.3f} m, y={y:.3f} m, yaw={np.degrees(yaw):.0f}°\n"
        f"cost {c.total:.1f} = curvature {c.curvature:.1f} + ratio {c.ratio:.1f} + miss {c.miss:.0f}"
        + "".join(f" + {name} {value:.1f}" for name, value in (("quality", c.quality), ("centring", c.centring)) if value)
        + f"  ({plan.curvature_mode} curvature, {plan.efd.harmonics} harmonics)",
        fontsize=10,
    )
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    return fig


def harmonics_figure(contour_xy, harmonics: Sequence[int] = (1, 2, 4, 8), *, curvature: str = "paper") -> Figure:
    """The thesis's Figure 4.5: one contour approximated with several harmonic counts.

    Parameters
    ----------
    contour_xy : (n, 2) float
        Polygon in meters, checked by :func:`contourgrasp.contour.clean_polygon`.
    harmonics : sequence of int
        One panel per count.
    curvature : {"paper", "geometric"}
        Flavour deciding the concave stretches (blue).

    Returns
    -------
    matplotlib.figure.Figure
        The scale bar's length follows the contour's size (2 cm for the thesis's objects).
    """
    contour = clean_polygon(contour_xy, check_units=False)
    scale = _scale_bar(float(np.max(np.ptp(contour, axis=0))))
    fig = Figure(figsize=(3.2 * len(harmonics), 3.6), layout="constrained")
    axes = fig.subplots(1, len(harmonics), sharex=True, sharey=True, squeeze=False)[0]
    for ax, k in zip(axes, harmonics):
        model = efd.fit(contour, k)
        ax.plot(*np.vstack([contour, contour[:1]]).T, color="0.7", lw=1)
        draw_efd(ax, model, curvature=curvature)
        ax.set_title(f"{k} harmonic{'s' if k > 1 else ''}")
        _finish_axes(ax, scale=scale)
    fig.suptitle(f"EFD approximation; concave stretches in blue ({curvature} curvature)", fontsize=10)
    return fig


def _to_pixels(result, points_xy, shift=(0, 0)) -> np.ndarray:
    """(n, 2) float: pixels of the plan's frame's points (n, 2) (:func:`contourgrasp.pipeline.plan_to_camera`), less
    ``shift``."""
    return result.camera.project(plan_to_camera(result.metric, result.view, result.grasp_height, points_xy)) - shift


def image_plan_figure(result, rgb=None) -> Figure:
    """An RGB-D plan: the image with contour, hand and grasp points (left), the metric plan (middle) and the height map.

    The third panel (:func:`draw_heights`) shows ``result.height_map`` under the planned
    hand's finger paths; without a height map (no table plane) the figure has the first two only.
    With a planned grasp height and a 3-D hand a fourth (:func:`draw_side_view`) shows each finger's
    open chain at that height over the scene's profile in the finger's own vertical plane. A side or
    tilted approach's plan is drawn in its approach frame (the middle panels: the outline and the map
    seen along it; "height" is then the distance toward the hand, :mod:`contourgrasp.perception.view_along`),
    and projected into the image at its grasp height.

    ``result`` is a :class:`contourgrasp.pipeline.ImageGraspPlan`; ``rgb`` the
    colour image (the depth-derived mask is shown when it is None). Over a
    colour image that segmentation registered to the depth image, everything
    is drawn less the colour offset, so that it lines up with the colour.
    """
    plan = result.plan
    heights = result.height_map if result.view is None else result.view.heights
    side = heights is not None and result.grasp_height is not None and plan.hand.is_3d
    if heights is None:
        fig = Figure(figsize=(16, 7), layout="constrained")
        image_ax, plan_ax = fig.subplots(1, 2, width_ratios=[1.2, 1])
    elif not side:
        fig = Figure(figsize=(22, 7), layout="constrained")
        image_ax, plan_ax, height_ax = fig.subplots(1, 3, width_ratios=[1.2, 1, 0.9])
    else:
        fig = Figure(figsize=(28, 7), layout="constrained")
        image_ax, plan_ax, height_ax, side_ax = fig.subplots(1, 4, width_ratios=[1.2, 1, 0.9, 0.9])
    seg = result.segmentation
    image_ax.imshow(rgb if rgb is not None else seg.mask, cmap="gray")
    shift = np.asarray(seg.colour_offset_px if rgb is not None and seg.colour_offset_px is not None else (0, 0))
    contour = np.vstack([seg.contour_px, seg.contour_px[:1]]) - shift
    outline = "footprint on the table" if seg.on_table else "contour"
    image_ax.plot(*contour.T, color="yellow", lw=1.2, label=f"{outline} ({seg.method})")
    for i, (finger, contact) in enumerate(zip(plan.hand.fingers, plan.fingers)):
        colour = FINGER_COLOURS[i % len(FINGER_COLOURS)]
        path = _to_pixels(result, to_image(finger.points(np.linspace(0, finger.travel, 30)), plan.pose), shift)
        image_ax.plot(*path.T, color=colour, lw=1.5, ls="--" if contact.missed else "-")
        image_ax.plot(*_to_pixels(result, [contact.start], shift)[0], "o", color=colour, mfc="white")
        grasp = _to_pixels(result, [contact.grasp_point], shift)[0]
        image_ax.plot(*grasp, "X" if contact.missed else "*", color=colour, ms=12, mec="black", mew=0.6)
        image_ax.annotate(finger.name, grasp, textcoords="offset points", xytext=(6, 6), color=colour, fontsize=9)
    pixels = np.vstack([contour, _to_pixels(result, [f.start for f in plan.fingers], shift)])
    lo, hi = pixels.min(axis=0) - 40, pixels.max(axis=0) + 40
    image_ax.set_xlim(max(lo[0], 0), min(hi[0], result.camera.width))
    image_ax.set_ylim(min(hi[1], result.camera.height), max(lo[1], 0))
    tilt = result.metric.tilt
    image_ax.set_title(f"camera image, approach depth {result.metric.approach_depth:.3f} m"
                       + ("" if tilt is None else f", table tilt {math.degrees(tilt):.1f}°"), fontsize=10)
    image_ax.legend(loc="upper left", fontsize=8)
    draw_plan(plan_ax, plan)
    _finish_axes(plan_ax)
    x, y, yaw = plan.pose
    where = f"in the {result.metric.frame} plane" if result.view is None else f"seen {result.approach.describe()}"
    plan_ax.set_title(f"{plan.hand.name} {where}: x={x:.3f} m, y={y:.3f} m, "
                      f"yaw={math.degrees(yaw):.0f}°, cost {plan.cost.total:.1f}", fontsize=10)
    plan_ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    along = result.view is not None
    if heights is not None:
        draw_heights(height_ax, heights, plan, fig, along=along)
    if side:
        draw_side_view(side_ax, heights, plan, result.grasp_height, along=along)
    return fig


#: Axis words of a map in the planning frame and in an approach frame (:mod:`contourgrasp.perception.view_along`).
HEIGHT_WORDS = {False: ("planning frame", "height above the table"),
                True: ("approach frame", "toward the hand from the reference plane")}


def draw_side_view(ax, heights, plan: GraspPlan, grasp_height: float, *, along: bool = False) -> None:
    """Each finger's body at the grasp height beside the scene, in the vertical plane the finger closes in.

    Horizontal: distance from the finger's knuckle along its chain's plane (:func:`~contourgrasp.hand.chain_plane`,
    toward the object); vertical: height above the table (``along``: an approach frame's, toward the hand from
    its reference plane). Per finger, in its colour: the height map's profile along that
    line (filled; unseen cells at their conservative bound, dotted) and its open chain's links.
    """
    hand = plan.hand
    palm_height = grasp_height + hand.open_tip_depth
    u = np.arange(-0.08, 0.14, 0.5 * heights.cell)
    bound = heights.conservative()
    for i, (finger, chain) in enumerate(zip(hand.fingers, hand.chains)):
        colour = FINGER_COLOURS[i % len(FINGER_COLOURS)]
        knuckle, direction = chain_plane(chain)
        line = to_image(knuckle + u[:, None] * direction, plan.pose)
        seen, hidden = heights.at(line), heights.at(line, bound)
        ax.fill_between(u, 0.0, np.nan_to_num(seen), color=colour, alpha=0.15, step="mid")
        ax.plot(u, np.where(np.isnan(seen), hidden, np.nan), color=colour, ls=":", lw=1)
        for a, b in chain_capsules(chain, 0.0)[0]:
            ua, ub = ((np.array([a[:2], b[:2]]) - knuckle) @ direction)
            ax.plot([ua, ub], [palm_height - a[2], palm_height - b[2]], color=colour, alpha=0.9,
                    lw=SIDE_VIEW_LINK_WIDTH, solid_capstyle="round", label=finger.name if a is not None else None)
    ax.axhline(0.0, color="black", lw=1)
    ax.axhline(palm_height, color="0.2", lw=2, label="palm underside")
    ax.axhline(grasp_height, color="tab:blue", ls=":", lw=1, label=f"grasp height {1e3 * grasp_height:.0f} mm")
    ax.set_aspect("equal")
    if along:  # the table, blocked along a horizontal approach, stands at BLOCKED: show the hand's reach
        ax.set_ylim(-0.01, 1.5 * palm_height)
    ax.set_xlabel("m along each finger's plane, from its knuckle")
    ax.set_ylabel(f"{HEIGHT_WORDS[along][1]} [m]")
    least = "" if plan.descent is None else (f", least clearance {1e3 * float(plan.descent.clearance[0].min()):.1f} mm "
                                              f"({plan.descent.bodies[int(np.argmin(plan.descent.clearance[0]))]})")
    ax.set_title(f"each finger's plane at the grasp{least}", fontsize=10)
    handles, labels = ax.get_legend_handles_labels()
    unique = dict(zip(labels, handles))
    ax.legend(unique.values(), unique.keys(), loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)


def draw_heights(ax, heights, plan: GraspPlan | None = None, fig: Figure | None = None, *, along: bool = False) -> None:
    """Draw a :class:`~contourgrasp.perception.HeightMap` on ``ax``, height-coloured, unseen cells grey.

    ``along``: the map is an approach frame's (its axes so labelled).
    With ``plan`` (planned in the same planning frame) the contour, the finger paths and the
    starts are drawn over it and the view is cropped to them; ``fig`` adds a colour bar.
    """
    x0, x1, y0, y1 = heights.extent
    cmap = matplotlib.colormaps["viridis"].with_extremes(bad="0.8")
    top = max(heights.max_height if np.isfinite(heights.max_height) else 0.0, 0.01)
    image = ax.imshow(1e3 * heights.heights, extent=(x0, x1, y1, y0), origin="upper", cmap=cmap, vmin=0.0,
                      vmax=1e3 * top, interpolation="nearest")
    if fig is not None:
        fig.colorbar(image, ax=ax, shrink=0.8, label=f"{HEIGHT_WORDS[along][1]} [mm] (grey: unseen)")
    if plan is not None:
        ax.plot(*np.vstack([plan.contour, plan.contour[:1]]).T, color="white", lw=1, label="contour")
        points = [plan.contour]
        for i, (finger, contact) in enumerate(zip(plan.hand.fingers, plan.fingers)):
            colour = FINGER_COLOURS[i % len(FINGER_COLOURS)]
            path = to_image(finger.points(np.linspace(0, finger.travel, 30)), plan.pose)
            ax.plot(*path.T, color=colour, lw=1.5, ls="--" if contact.missed else "-")
            ax.plot(*contact.start, "o", color=colour, mfc="white")
            points.append(path)
        lo, hi = np.vstack(points).min(axis=0) - 0.03, np.vstack(points).max(axis=0) + 0.03
        ax.set_xlim(max(lo[0], x0), min(hi[0], x1))
        ax.set_ylim(min(hi[1], y1), max(lo[1], y0))
    ax.set_aspect("equal")
    ax.set_xlabel(f"x [m] ({HEIGHT_WORDS[along][0]})")
    ax.set_ylabel("y [m]")
    obstacles = f", obstacles up to {1e3 * heights.obstacle_max_height:.0f} mm" if heights.obstacles.any() else ""
    ax.set_title(f"height map ({1e3 * heights.cell:g} mm cells): object up to "
                 f"{1e3 * heights.max_height:.0f} mm{obstacles}", fontsize=10)


def doctor_figure(diagnosis) -> Figure:
    """What ``contourgrasp doctor`` saw (:class:`contourgrasp.doctor.Diagnosis`): the colour with every candidate
    (green: wholly in view, grey: touching the border, yellow: the target) and the plan's fingers; the depth with its
    missing readings (red beside depth edges, magenta elsewhere); the heights above the support surface."""
    fig = Figure(figsize=(21, 6.5), layout="constrained")
    colour_ax, depth_ax, height_ax = fig.subplots(1, 3)
    missing = diagnosis.missing
    colour_ax.imshow(diagnosis.rgb if diagnosis.rgb is not None else ~missing, cmap="gray")
    support, result = diagnosis.support, diagnosis.result
    target = None if result is None or result.target is None else result.target.label
    for c in () if support is None else support.candidates:
        outline = np.vstack([c.contour_px, c.contour_px[:1]])
        colour = "yellow" if c.label == target else "lime" if c.in_view else "0.6"
        colour_ax.plot(*outline.T, color=colour, lw=2.0 if c.label == target else 1.0)
        colour_ax.annotate(str(c.label), c.centroid_px, color=colour, fontsize=9, ha="center")
    if result is not None:
        for i, (finger, contact) in enumerate(zip(result.plan.hand.fingers, result.plan.fingers)):
            path = _to_pixels(result, to_image(finger.points(np.linspace(0, finger.travel, 30)), result.plan.pose))
            colour_ax.plot(*path.T, color=FINGER_COLOURS[i % len(FINGER_COLOURS)], lw=1.5,
                           ls="--" if contact.missed else "-")
    colour_ax.set_title("colour: candidates (green: in view, grey: at the border, yellow: the target)")
    valid = np.where(missing, np.nan, 0.0)
    depth_ax.imshow(valid, cmap="gray")
    shown = np.zeros((*missing.shape, 4))
    shown[missing & ~diagnosis.edge_missing] = (1.0, 0.0, 1.0, 0.8)
    shown[diagnosis.edge_missing] = (1.0, 0.0, 0.0, 0.9)
    depth_ax.imshow(shown)
    depth_ax.set_title(f"missing depth {100 * missing.mean():.0f} % (red: beside depth edges)")
    if support is not None:
        plane = support.plane
        inliers = plane.inliers if plane.inliers.shape == missing.shape else np.zeros_like(missing)
        heights = np.full(missing.shape, np.nan)
        for c in support.candidates:
            heights[c.mask] = c.height
        image = height_ax.imshow(np.where(inliers, 0.0, heights), cmap="viridis", vmin=0.0)
        fig.colorbar(image, ax=height_ax, shrink=0.8, label="candidate height above the support [m] (0: on it)")
        height_ax.set_title(f"support surface, tilted {math.degrees(plane.tilt):.1f} deg")
    else:
        height_ax.set_title("no support surface found")
    for ax in (colour_ax, depth_ax, height_ax):
        ax.set_xticks([])
        ax.set_yticks([])
    return fig
