"""`make demo`: plan grasps on every built-in example contour with every hand preset.

Runs the `contourgrasp` command exactly as a user would and writes, to the
output folder (default demo-output/): bar_clamp-plan.json and .png, the full
RGB-D pipeline (`contourgrasp plan`) on the bundled frame examples/bar_clamp;
<contour>-<hand>.json and .png for each pair, efd-<contour>.png (the thesis's Figure 4.5) for each contour, and
summary.md, a table of what was planned. Every plan uses the command's default
planner, `default` (src/contourgrasp/data/planners/default.toml).
"""

import argparse
import contextlib
import io
import json
import sys
from pathlib import Path

from contourgrasp.cli import main as contourgrasp
from contourgrasp.io.contour_file import example_names
from contourgrasp.io.hand_file import preset_names


def run(*argv) -> tuple[int, str]:
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        code = contourgrasp([str(a) for a in argv])
    return code, err.getvalue().strip()


def main(out: Path) -> int:
    out.mkdir(parents=True, exist_ok=True)
    rows = ["| contour | hand | x [m] | y [m] | yaw [deg] | cost | fingers touching | concave | time [ms] |",
            "|---|---|---|---|---|---|---|---|---|"]
    for contour in example_names():
        code, err = run("efd", "--contour", f"example:{contour}", "--plot", out / f"efd-{contour}.png")
        if code:
            print(err, file=sys.stderr)
            return code
        for hand in preset_names():
            stem = out / f"{contour}-{hand}"
            code, err = run("synth", "--contour", f"example:{contour}", "--hand", hand, "--out", f"{stem}.json", "--plot", f"{stem}.png")
            if code == 3:
                rows.append(f"| {contour} | {hand} | {err.removeprefix('contourgrasp: ')} |||||||")
                continue
            if code:
                print(err, file=sys.stderr)
                return code
            plan = json.loads(Path(f"{stem}.json").read_text())
            pose, fingers = plan["pose"], plan["fingers"]
            touching = sum(not f["missed"] for f in fingers)
            concave = sum(f["concave"] and not f["missed"] for f in fingers)
            rows.append(f"| {contour} | {hand} | {pose['x']:.3f} | {pose['y']:.3f} | "
                        f"{pose['yaw'] * 57.29577951308232:.0f} | {plan['cost']['total']:.1f} | "
                        f"{touching}/{len(fingers)} | {concave} | {plan['timing_ms']['total']:.0f} |")
            print(f"{contour:8s} {hand:26s} -> {stem}.png")
    frame = Path(__file__).resolve().parents[1] / "examples" / "bar_clamp"
    code, err = run("plan", "--rgb", frame / "color_0.png", "--depth", frame / "depth_0.npy",
                    "--intrinsics", frame / "primesense_overhead_color.intr",
                    "--extrinsics", frame / "primesense_overhead_to_world.tf", "--out", out / "bar_clamp-plan.json", "--plot", out / "bar_clamp-plan.png")
    if code:
        print(err, file=sys.stderr)
        return code
    print(f"RGB-D frame examples/bar_clamp -> {out}/bar_clamp-plan.png")
    (out / "summary.md").write_text("\n".join(rows) + "\n")
    print(f"wrote {out}/summary.md")
    return 0


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default="demo-output", help="output folder (default demo-output)")
    sys.exit(main(Path(parser.parse_args().out)))
