"""Write the simulated hand's present geometry into the ray presets' hand files.

Each preset's 2-D fingers are given chains and a palm by
``contourgrasp.sim.tendon_hand.derive_body`` with the default ``ChainRule`` -- exactly what
``build_hand`` built from the 2-D preset before the hand files carried their bodies -- and
the ``[fingers.chain]`` and ``[palm]`` tables are written into the preset's TOML (comments
kept; earlier generated tables replaced). Floats are written exactly (``repr``), so the
simulated hand built from the file is bit for bit the one derived.

    .venv/bin/python tools/derive_hand_chains.py            # rewrite the presets
    .venv/bin/python tools/derive_hand_chains.py --check    # exit 1 if a preset differs

The curved-thumb preset is left 2-D: its thumb closes on an arc, which no planar chain
follows and the simulation does not build.
"""

from __future__ import annotations

import argparse
import sys
from dataclasses import replace
from pathlib import Path

import contourgrasp
from contourgrasp.io.hand_file import chain_toml, palm_toml, parse_hand
from contourgrasp.sim.tendon_hand import derive_body

PRESETS = ("five-finger-linear", "three-finger")
HAND_DIR = Path(contourgrasp.__file__).parent / "data" / "hands"
MARK = "# 3-D body: the simulated hand's geometry, written by tools/derive_hand_chains.py"


def strip_body(text: str) -> str:
    """``text`` without its ``[fingers.chain]`` and ``[palm]`` tables and the generated-body comment."""
    out, skipping = [], False
    for line in text.splitlines():
        header = line.strip()
        if header.startswith("["):
            skipping = header in ("[fingers.chain]", "[palm]")
        if not skipping and line != MARK:
            out.append(line)
    while out and not out[-1].strip():
        out.pop()
    # drop blank runs left where a table was cut
    cleaned = []
    for line in out:
        if not line.strip() and cleaned and not cleaned[-1].strip():
            continue
        cleaned.append(line)
    return "\n".join(cleaned) + "\n"


def with_body(text: str) -> str:
    """The preset text with the derived chains after each finger and the palm at the end."""
    base = strip_body(text)
    hand = parse_hand(base)
    body = derive_body(replace(hand, chains=None, palm=None))
    blocks, finger = [], -1
    lines = base.rstrip("\n").split("\n")
    for k, line in enumerate(lines):
        if line.strip() == "[[fingers]]" and finger >= 0:
            _insert_chain(blocks, body, finger)
        if line.strip() == "[[fingers]]":
            finger += 1
        blocks.append(line)
        if k == len(lines) - 1:
            _insert_chain(blocks, body, finger)
    while blocks and not blocks[-1].strip():
        blocks.pop()
    blocks += ["", MARK, *palm_toml(body.palm)[1:]]
    return "\n".join(blocks) + "\n"


def _insert_chain(blocks: list[str], hand, index: int) -> None:
    while blocks and not blocks[-1].strip():
        blocks.pop()
    blocks += chain_toml(hand.chains[index], hand.fingers[index]) + [""]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--check", action="store_true", help="only check that the presets are up to date")
    args = parser.parse_args(argv)
    stale = []
    for name in PRESETS:
        path = HAND_DIR / f"{name}.toml"
        text = path.read_text(encoding="utf-8")
        new = with_body(text)
        if new != text:
            stale.append(name)
            if not args.check:
                path.write_text(new, encoding="utf-8")
    verb = "out of date" if args.check else "rewritten"
    print(f"{verb}: {', '.join(stale) or 'none'}")
    return 1 if args.check and stale else 0


if __name__ == "__main__":
    sys.exit(main())
