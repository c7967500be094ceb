"""Adaptive harmonics (thesis 6.1 item 3): the figure and the sweep behind the default tolerance.

Figure (``docs/adaptive-harmonics.png``)::

    python tools/harmonics_figure.py [--out docs/adaptive-harmonics.png]

One row per contour (stone 1, stone 2, stone 2 as a camera sees it, the can):
the polygon with the thesis's 4-harmonic EFD (left), with the adaptive one
(middle), concave stretches in blue as in :func:`contourgrasp.visualize.harmonics_figure`,
and the rule's left-out RMS distance e(N) against N with the tolerance (right).
This is Figures 4.5/4.6 of the thesis, answered per object.

Sweep (its tables chose the tolerance; ``docs/studies.md`` has the reading)::

    python tools/harmonics_figure.py --sweep [--sim]

For every example contour and tolerance: the N chosen for the clean contour,
for the contour rasterised at 1.5 mm per pixel and outlined like a camera
mask (:func:`contourgrasp.perception.mask_contour`), and with 1 mm and 2 mm of
Gaussian noise along the normal every 3 mm (min-max over ``--draws`` draws).
``--sim`` adds the contours the simulated camera segments
(:mod:`contourgrasp.sim`, noisy depth, default perception) for the thesis's
objects.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import cv2
import numpy as np
from matplotlib.figure import Figure

from contourgrasp import contour, example_contour, example_names, tolerances
from contourgrasp.perception import mask_contour
from contourgrasp.visualize import CONCAVE_COLOUR, CONVEX_COLOUR, draw_efd

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "docs" / "adaptive-harmonics.png"
PIXEL = 0.0015  # m per pixel: ~1 px of a 640 x 480 depth camera at 0.6-0.7 m
JITTER_SPACING = 0.003  # m between noisy points
TOLERANCES = {"rms": (0.005, 0.006, 0.007, 0.0075, 0.008, 0.009, 0.010, 0.012, 0.015),
              "power": (5e-5, 1e-4, 1.5e-4, 2e-4, 3e-4, 5e-4, 1e-3)}
SIM_OBJECTS = ("can", "case", "bottle", "stone1", "stone2")


def resample(points: np.ndarray, count: int) -> np.ndarray:
    """(count, 2) float: points evenly spaced by arc length along a closed polygon."""
    closed = np.vstack([points, points[:1]])
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(closed, axis=0), axis=1))])
    u = np.linspace(0.0, s[-1], count, endpoint=False)
    return np.c_[np.interp(u, s, closed[:, 0]), np.interp(u, s, closed[:, 1])]


def camera_staircase(points: np.ndarray, rng: np.random.Generator, pixel: float = PIXEL) -> np.ndarray:
    """The outline a camera mask of the polygon gives: rasterised at ``pixel`` m, random sub-pixel offset."""
    q = (points - points.min(axis=0)) / pixel + 4.0 + rng.uniform(0.0, 1.0, 2)
    height, width = (np.ceil(q.max(axis=0)) + 5).astype(int)[::-1]
    mask = np.zeros((height, width), np.uint8)
    cv2.fillPoly(mask, [np.round(q * 16).astype(np.int32)], 1, lineType=cv2.LINE_8, shift=4)
    return mask_contour(mask) * pixel


def jittered(points: np.ndarray, sigma: float, rng: np.random.Generator, spacing: float = JITTER_SPACING) -> np.ndarray:
    """The polygon resampled every ``spacing`` m, each point moved along the normal by N(0, sigma)."""
    perimeter = np.sum(np.linalg.norm(np.diff(np.vstack([points, points[:1]]), axis=0), axis=1))
    q = resample(points, int(np.ceil(perimeter / spacing)))
    tangent = np.roll(q, -1, axis=0) - np.roll(q, 1, axis=0)
    normal = np.c_[tangent[:, 1], -tangent[:, 0]] / np.linalg.norm(tangent, axis=1)[:, None]
    for _ in range(1000):
        noisy = q + normal * rng.normal(0.0, sigma, (len(q), 1))
        if contour.first_self_intersection(noisy) is None:
            return noisy
    raise RuntimeError(f"no simple polygon with {sigma} m of noise")


def left_out(points: np.ndarray, upper: int = tolerances.HARMONICS_BOUNDS[1]) -> np.ndarray:
    """(upper + 1,) float: e(N) / sqrt(area) for N = 0..upper (the "rms" rule's measure)."""
    power = contour.harmonic_power(contour.fit(points, upper))
    tail = np.append(np.cumsum(power[::-1])[::-1], 0.0)
    return np.sqrt(tail / abs(contour.signed_area(contour.clean_polygon(points, check_units=False))))


def sim_contours(names=SIM_OBJECTS, seeds=range(3)) -> dict[str, list[np.ndarray]]:
    """Contours (m) the simulated camera segments for each object, one per seed."""
    from contourgrasp.sim import build_scene, render
    from contourgrasp.pipeline import perceive

    out = {}
    for name in names:
        out[name] = []
        for seed in seeds:
            scene = build_scene(name, seed=seed)
            rgb, depth = render(scene, sensor="basic", seed=seed)
            out[name].append(perceive(rgb, depth, scene.camera.intrinsics)[1].contour_xy)
    return out


def _span(values) -> str:
    lo, hi = min(values), max(values)
    return f"{lo}" if lo == hi else f"{lo}-{hi}"


def sweep(draws: int = 5, sim: bool = False) -> str:
    """Markdown tables: N per contour and tolerance, for both rules."""
    rng = np.random.default_rng(2024)
    variants = {}
    for name in example_names():
        clean = example_contour(name)
        variants[name] = {
            "clean": [clean],
            "camera 1.5 mm px": [camera_staircase(clean, rng) for _ in range(draws)],
            "1 mm noise": [jittered(clean, 0.001, rng) for _ in range(draws)],
            "2 mm noise": [jittered(clean, 0.002, rng) for _ in range(draws)],
        }
    if sim:
        for name, contours in sim_contours(seeds=range(draws)).items():
            variants[name]["sim camera"] = contours
    columns = list(dict.fromkeys(c for v in variants.values() for c in v))
    lines = []
    for rule, tols in TOLERANCES.items():
        default = tolerances.HARMONICS_RMS_TOLERANCE if rule == "rms" else tolerances.HARMONICS_POWER_TOLERANCE
        lines += [f"rule {rule!r}: N for each tolerance; cells {' / '.join(columns)}", ""]
        lines.append("| contour | " + " | ".join(f"{t:g}" + (" (default)" if t == default else "") for t in tols) + " |")
        lines.append("|---" * (len(tols) + 1) + "|")
        for name, by_kind in variants.items():
            cells = []
            for t in tols:
                cells.append(" / ".join(
                    _span([contour.choose_harmonics(p, rule=rule, tolerance=t) for p in by_kind[c]]) if c in by_kind else "-"
                    for c in columns))
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
        lines.append("")
        lines += [f"rule {rule!r} at the default tolerance {default:g}", ""]
        lines.append("| contour | " + " | ".join(columns) + " |")
        lines.append("|---" * (len(columns) + 1) + "|")
        for name, by_kind in variants.items():
            cells = [_span([contour.choose_harmonics(p, rule=rule) for p in by_kind[c]]) if c in by_kind else "-"
                     for c in columns]
            lines.append(f"| {name} | " + " | ".join(cells) + " |")
        lines.append("")
    return "\n".join(lines)


def concave_runs(model: contour.EFD, samples: int = 2048) -> int:
    """Number of separate concave stretches of the EFD curve."""
    t = np.linspace(0.0, model.T, samples, endpoint=False)
    c = contour.concave(model, t)
    if c.all():
        return 1
    return int(np.sum(c & ~np.roll(c, 1)))


def figure() -> Figure:
    rng = np.random.default_rng(7)
    rows = [
        ("stone 1 (simple)", example_contour("stone1")),
        ("stone 2 (complex)", example_contour("stone2")),
        ("stone 2, camera staircase 1.5 mm/px", camera_staircase(example_contour("stone2"), rng)),
        ("can (flat sides)", example_contour("can")),
    ]
    lower, upper = tolerances.HARMONICS_BOUNDS
    tolerance = tolerances.HARMONICS_RMS_TOLERANCE
    fig = Figure(figsize=(11.5, 3.3 * len(rows)), layout="constrained")
    axes = fig.subplots(len(rows), 3, width_ratios=[1, 1, 0.9])
    for (title, contour), (thesis_ax, adaptive_ax, error_ax) in zip(rows, axes):
        contour = contour.clean_polygon(contour, check_units=False)
        n = contour.choose_harmonics(contour)
        for ax, k, label in ((thesis_ax, 4, "thesis: 4 harmonics"), (adaptive_ax, n, f"adaptive: {n} harmonics")):
            model = contour.fit(contour, k)
            ax.plot(*np.vstack([contour, contour[:1]]).T, color="0.7", lw=1)
            draw_efd(ax, model)
            runs = concave_runs(model)
            ax.set_title(f"{title}\n{label}, {runs} concave stretch{'es' if runs != 1 else ''}", fontsize=9)
            ax.set_aspect("equal")
            ax.autoscale_view()
            ax.invert_yaxis()
            ax.tick_params(labelsize=7)
            ax.grid(alpha=0.3)
        e = left_out(contour) * 100
        ns = np.arange(1, upper)  # e(upper) = 0 by definition
        error_ax.semilogy(ns, np.maximum(e[1:upper], 1e-2), "o-", color="0.4", ms=4)  # 0 (symmetry) at the axis
        error_ax.axhline(tolerance * 100, color="tab:red", lw=1, ls="--", label=f"tolerance {tolerance * 100:g} %")
        error_ax.axvspan(lower - 0.5, upper + 0.5, color="tab:green", alpha=0.06, label=f"bounds {lower}-{upper}")
        error_ax.plot(n, max(e[n], 1.2e-2), "o", color="tab:red", ms=9, mfc="none", mew=2, label=f"chosen N = {n}")
        error_ax.plot(4, max(e[4], 1e-3), "s", color="0.2", ms=7, mfc="none", label="thesis N = 4")
        error_ax.set_xticks(np.arange(1, upper + 1))
        error_ax.set_ylim(1e-2, 30)
        error_ax.set_xlabel("harmonics N", fontsize=8)
        error_ax.set_ylabel("e(N) / sqrt(area) [%]", fontsize=8)
        error_ax.tick_params(labelsize=7)
        error_ax.grid(alpha=0.3, which="both")
        error_ax.legend(fontsize=7, loc="upper right")
    thesis_ax.plot([], [], color=CONVEX_COLOUR, lw=2, label="EFD convex")
    thesis_ax.plot([], [], color=CONCAVE_COLOUR, lw=2, label="EFD concave")
    thesis_ax.plot([], [], color="0.7", lw=1, label="input polygon")
    thesis_ax.legend(fontsize=7, loc="lower left")
    fig.suptitle("Adaptive harmonics (contour.choose_harmonics, 'rms' rule): the fewest N in "
                 f"{lower}-{upper} whose left-out RMS detail\ne(N) = sqrt(P_N+1 + ... + P_{upper}) is at most "
                 f"{tolerance:g} x sqrt(area); concave stretches in blue (paper curvature), y down as the camera sees",
                 fontsize=10)
    return fig


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=OUT, help="figure path (default %(default)s)")
    parser.add_argument("--sweep", action="store_true", help="print the tolerance sweep instead of drawing")
    parser.add_argument("--sim", action="store_true", help="with --sweep: add the simulated camera's contours")
    parser.add_argument("--draws", type=int, default=5, help="noisy draws per contour (default %(default)s)")
    args = parser.parse_args(argv)
    if args.sweep:
        print(sweep(args.draws, args.sim))
        return
    args.out.parent.mkdir(parents=True, exist_ok=True)
    figure().savefig(args.out, dpi=110)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
