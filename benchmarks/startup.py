"""Start-up time of the `contourgrasp` command and of `import contourgrasp`, whole process.

Each command runs ``--runs`` times as a new process (what a user's shell or a
script calling the CLI per frame pays); the first, uncounted run fills
numba's on-disk cache. Prints the median and the spread in a Markdown table.

    .venv/bin/python benchmarks/startup.py [--runs 9]
"""

import argparse
import statistics
import subprocess
import sys
import time
from pathlib import Path

BIN = Path(sys.executable).parent
CASES = {
    "python -c pass (the interpreter alone)": [sys.executable, "-c", "pass"],
    "import contourgrasp": [sys.executable, "-c", "import contourgrasp"],
    "contourgrasp hands": [str(BIN / "contourgrasp"), "hands"],
    "contourgrasp synth (can, three-finger, paper planner)": [
        str(BIN / "contourgrasp"), "synth", "--contour", "example:can", "--hand", "three-finger", "--planner", "paper"],
    "contourgrasp synth (can, five-finger-linear, default planner)": [
        str(BIN / "contourgrasp"), "synth", "--contour", "example:can", "--hand", "five-finger-linear"],
}


def wall_times(command: list[str], runs: int) -> list[float]:
    subprocess.run(command, check=True, capture_output=True)
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        subprocess.run(command, check=True, capture_output=True)
        times.append(time.perf_counter() - start)
    return times


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--runs", type=int, default=9)
    args = parser.parse_args()
    print("| command | median [s] | min–max [s] |\n|---|---|---|")
    for name, command in CASES.items():
        t = wall_times(command, args.runs)
        print(f"| `{name}` | {statistics.median(t):.2f} | {min(t):.2f}–{max(t):.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
