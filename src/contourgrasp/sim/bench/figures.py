"""Figures of the bench: success rates (per object, per split), and trials in pictures.

Matplotlib ``Figure`` objects built without pyplot, like :mod:`contourgrasp.visualize`;
imported only when :func:`~contourgrasp.sim.bench.report.write_outputs` draws them.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from ...hand import to_image
from ...pipeline import plan_to_camera
from ...tolerances import FELL_OFF_TABLE
from ...visualize import FINGER_COLOURS
from .config import SHORT_CAUSES, Bench, label
from .stats import records, sort_planner, success_rates, thesis_rates, wilson_interval

#: Pixels around the object and the open hand in the camera panels.
CROP_MARGIN = 30
THESIS_COLOUR = "0.75"
PLANNER_COLOURS = ("tab:blue", "tab:green", "tab:orange", "tab:red", "tab:purple", "tab:brown", "tab:pink")
#: Inches per bar of :func:`objects_figure`, and failed trials per row of :func:`failures_figure`.
BAR_HEIGHT, TILES_PER_ROW = 0.16, 2


def success_figure(bench: Bench, results) -> Figure:
    """Success rate per object (groups) and planner (bars), Table 4.4's rate first where it has one."""
    objects = [o.name for o in bench.objects]
    series = [("thesis (Table 4.4, real robot)", thesis_rates(objects), THESIS_COLOUR)]
    series += [(p, success_rates(results, p, objects), PLANNER_COLOURS[i % len(PLANNER_COLOURS)])
               for i, p in enumerate(bench.planners)]
    groups = [*objects, "all"]
    width = 0.8 / len(series)
    fig = Figure(figsize=(max(8.0, 1.9 * len(groups) + 2), 4.6), layout="constrained")
    ax = fig.add_subplot()
    for k, (name, rates, colour) in enumerate(series):
        x = np.arange(len(groups)) + (k - (len(series) - 1) / 2) * width
        heights = [100 * (rates[g] if rates[g] is not None else np.nan) for g in groups]
        bars = ax.bar(x, heights, width, label=name, color=colour, edgecolor="black", linewidth=0.5,
                      hatch="//" if k == 0 else None)
        ax.bar_label(bars, fmt="%.0f", fontsize=7, padding=1)
    ax.set_xticks(np.arange(len(groups)), [label(g) for g in groups])
    ax.set_ylim(0, 110)
    ax.set_ylabel("success rate [%]")
    ax.set_title(f"Grasp success: {bench.trials} simulated trial(s) per object and planner,\n"
                 f"hand {bench.hand.name}; the thesis's rates from a real robot", fontsize=10)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=8)
    ax.grid(axis="y", alpha=0.3)
    return fig


def trials_figure(bench: Bench, snapshots) -> Figure:
    """A row per planner, its snapshots side by side: the camera's picture with the plan, the end from the side."""
    planners = list(dict.fromkeys(snap.result.planner for snap in snapshots)) or [None]
    per_row = max([sum(snap.result.planner == p for snap in snapshots) for p in planners] + [1])
    fig = Figure(figsize=(8.5 * per_row, 3.4 * len(planners)), layout="constrained")
    axes = fig.subplots(len(planners), 2 * per_row, squeeze=False, width_ratios=[1, 1.25] * per_row)
    for row, planner in zip(axes, planners):
        own = [snap for snap in snapshots if snap.result.planner == planner]
        for k, snap in enumerate(own):
            draw_camera_panel(row[2 * k], snap, bench.hand)
            draw_side_panel(row[2 * k + 1], snap)
    if not snapshots:
        axes[0, 0].text(0.5, 0.5, "no trial had a plan", ha="center", va="center")
    for ax in axes.ravel():
        ax.set_axis_off()
    return fig


def objects_figure(bench: Bench, results) -> Figure:
    """Success rate per object, a panel per split: horizontal bars per planner, objects by the ranking planner's rate.

    Each panel's title gives every planner's rate on the split with its 95 % Wilson interval.
    """
    named = {m for _, members in bench.splits for m in members}
    other = tuple(o.name for o in bench.objects if o.name not in named)
    groups = [*bench.splits, *((("other", other),) if other else ())]
    ranking = sort_planner(bench)
    rates = {p: success_rates(results, p, [o.name for o in bench.objects]) for p in bench.planners}
    heights = [len(members) * (len(bench.planners) + 1) * BAR_HEIGHT + 1.0 for _, members in groups]
    fig = Figure(figsize=(8.0, sum(heights) + 0.6), layout="constrained")
    axes = fig.subplots(len(groups), 1, squeeze=False, height_ratios=heights)[:, 0]
    step = 1.0 / (len(bench.planners) + 1)
    for ax, (split, members) in zip(axes, groups):
        order = sorted(members, key=lambda o: (rates[ranking][o], -members.index(o)))
        for k, planner in enumerate(bench.planners):
            y = np.arange(len(order)) + (len(bench.planners) - 1 - 2 * k) * step / 2
            ax.barh(y, [100 * rates[planner][o] for o in order], step, label=planner,
                    color=PLANNER_COLOURS[k % len(PLANNER_COLOURS)], edgecolor="black", linewidth=0.4)
        ax.set_yticks(np.arange(len(order)), [label(o) for o in order], fontsize=7)
        ax.set_xlim(0, 100)
        ax.set_xlabel("success rate [%]", fontsize=8)
        ax.grid(axis="x", alpha=0.3)
        summary = "\n".join(f"{p} {_split_rate(results, p, members)}" for p in bench.planners)
        ax.set_title(f"{split} ({len(members)} objects, {bench.trials} trials each)\n{summary}", fontsize=8)
    axes[0].legend(loc="lower right", fontsize=7)
    return fig


def _split_rate(results, planner: str, members) -> str:
    own = [r for r in records(results, planner) if r.object in members]
    wins = sum(r.success for r in own)
    low, high = wilson_interval(wins, len(own))
    return f"{100 * wins / len(own):.0f} % ({100 * low:.0f}–{100 * high:.0f})"


def failures_figure(bench: Bench, snapshots) -> Figure:
    """A mosaic of failed trials, :data:`TILES_PER_ROW` to a row: the camera's picture with the plan, the end."""
    rows = max(1, -(-len(snapshots) // TILES_PER_ROW))
    fig = Figure(figsize=(8.5 * TILES_PER_ROW, 3.4 * rows), layout="constrained")
    axes = fig.subplots(rows, 2 * TILES_PER_ROW, squeeze=False, width_ratios=[1, 1.25] * TILES_PER_ROW)
    for k, snap in enumerate(snapshots):
        row, column = divmod(k, TILES_PER_ROW)
        draw_camera_panel(axes[row, 2 * column], snap, bench.hand)
        draw_side_panel(axes[row, 2 * column + 1], snap)
    if not snapshots:
        axes[0, 0].text(0.5, 0.5, "no failed trial had a plan", ha="center", va="center")
    for ax in axes.ravel():
        ax.set_axis_off()
    return fig


def draw_camera_panel(ax, snap, hand) -> None:
    """The planner's picture, cropped, with the object's contour and the hand's finger paths at the plan."""
    planned = snap.planned
    contour = np.vstack([planned.segmentation.contour_px, planned.segmentation.contour_px[:1]])
    ax.imshow(snap.rgb)
    ax.plot(*contour.T, color="yellow", lw=1.0)
    starts = []
    for i, finger in enumerate(hand.fingers):
        colour = FINGER_COLOURS[i % len(FINGER_COLOURS)]
        path = _pixels(planned, to_image(finger.points(np.linspace(0.0, finger.travel, 20)), planned.pose))
        ax.plot(*path.T, color=colour, lw=1.4)
        ax.plot(*path[0], "o", color=colour, mfc="white", ms=4)
        starts.append(path[0])
    if planned.plan is not None:
        for i, contact in enumerate(planned.plan.fingers):
            point = _pixels(planned, [contact.grasp_point])[0]
            ax.plot(*point, "X" if contact.missed else "*", color=FINGER_COLOURS[i % len(FINGER_COLOURS)], ms=9,
                    mec="black", mew=0.5)
    seen = np.vstack([contour, starts])
    low, high = seen.min(axis=0) - CROP_MARGIN, seen.max(axis=0) + CROP_MARGIN
    height, width = snap.rgb.shape[:2]
    ax.set_xlim(max(low[0], 0), min(high[0], width))
    ax.set_ylim(min(high[1], height), max(low[1], 0))
    result = snap.result
    ax.set_title(f"{result.planner}: {label(result.record.object)}, trial {result.trial + 1} (seed "
                 f"{result.record.seed})", fontsize=9)


def _outcome(record) -> str:
    """A trial's outcome in a few words: held or why not, how far it rose and moved, the fingers on it; a clearing
    run's objects cleared, its end and its last attempt's cause."""
    if record.ended is not None:
        last = "" if record.cause is None else f"; last: {SHORT_CAUSES[record.cause]}"
        return f"cleared {record.cleared}/{record.scene_objects}: {record.ended}{last}"
    outcome = "held" if record.success else f"failed: {SHORT_CAUSES[record.cause]}"
    moved = ("knocked off the table" if record.lift < -FELL_OFF_TABLE else
             f"lifted {100 * record.lift:.1f} cm, moved {1000 * record.hold_drift:.0f} mm in the hand")
    return f"{outcome}; {moved}; touching: {', '.join(record.fingers_in_contact) or 'none'}"


def draw_side_panel(ax, snap) -> None:
    """The scene at the end of the trial from the side (white where nothing is seen), with the outcome."""
    ax.imshow(np.where(snap.hit[..., None], snap.view, 255).astype(np.uint8))
    ax.set_title(_outcome(snap.result.record), fontsize=8)


def _pixels(planned, points_xy) -> np.ndarray:
    """(n, 2) float: pixels of the plan's frame's points (n, 2) (:func:`contourgrasp.pipeline.plan_to_camera`)."""
    return planned.camera.project(plan_to_camera(planned.metric, planned.view, planned.grasp_height, points_xy))
