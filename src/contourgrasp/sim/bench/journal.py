"""The bench's journal: every finished trial appended to ``trials.jsonl`` as it ends, so a bench can resume.

The first line holds the bench's settings (:func:`settings`), every next line
one trial (:func:`~contourgrasp.sim.bench.report.trial_to_dict`), written and
flushed to disk as the trial ends. A bench killed mid-run leaves at worst a
torn last line, which :func:`resume` drops; it refuses a journal of another
bench configuration before touching anything.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
from pathlib import Path
from typing import Annotated

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError

from ...errors import SimulationError
from ...validation import shown
from ..planners import synthesis_planner
from .config import Bench, BenchTrial
from .report import trial_from_dict, trial_to_dict

#: File name of the journal in the bench's output folder.
JOURNAL = "trials.jsonl"


class _Pose(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)
    x: float
    y: float
    yaw: float


class _TrialLine(BaseModel):
    """The fields and types of a journal's trial line (:func:`~contourgrasp.sim.bench.report.trial_to_dict`)."""

    model_config = ConfigDict(extra="forbid", strict=True)
    object: str
    planner: str
    trial: int = Field(ge=0)
    seed: int
    success: bool
    cause: str | None
    fingers_in_contact: list[str]
    first_contact: list[Annotated[tuple[str, float], Field(strict=False)]]  # JSON writes a pair as a list
    push: float
    lift: float
    hold_drift: float
    approach_depth: float | None
    grasp_height: float | None = None
    plan_error: str | None
    sim_time: float
    plan_time: float
    wall_time: float
    pose: _Pose | None
    outcomes: list[bool] = []
    detected: list[bool] = []
    scene_objects: int | None = None
    cleared: int | None = None
    ended: str | None = None


def settings(bench: Bench) -> dict:
    """What decides a bench's trials, by setting name: two benches with equal settings run the same trials.

    Object and hand geometry, planner options and scene parameters enter as
    short digests beside the names a reader recognises. The scene's kind is
    named only when it is not ``single``, the attempts only when more than
    one and the protocol only when not ``trials``, so journals written before there were kinds, attempts
    or protocols resume.
    """
    kind = {} if bench.scene_kind == "single" else {"scene": bench.scene_kind}
    return kind | {
        "objects": [o.name for o in bench.objects],
        "object geometry": [f"{o.name} {digest(o)}" for o in bench.objects],
        "planners": list(bench.planners),
        "planner settings": [f"{p} {digest(synthesis_planner(p))}" for p in bench.planners],
        "trials": bench.trials,
        "seed": bench.seed,
        "hand": f"{bench.hand.name} {digest(bench.hand)}",
        "sensor": bench.sensor,
        **({} if bench.tilt is None else {"tilt": bench.tilt}),
        **({"robot in view": True} if bench.robot else {}),
        **({"attempts": bench.attempts} if bench.attempts > 1 else {}),
        **({"protocol": bench.protocol} if bench.protocol != "trials" else {}),
        "camera": digest(bench.camera),
        "workspace": digest(bench.workspace),
        **({} if bench.hand_model is None else
           {"hand model": f"{Path(bench.hand_model.path).name} {digest(bench.hand_model.derivation.mount)}"}),
    }


def digest(value) -> str:
    """12 hex digits naming ``value``'s content (dataclasses, arrays, sequences, dicts and scalars), stable across runs.

    Examples
    --------
    >>> digest((1.0, "a")) == digest([1.0, "a"]), digest(1.0) == digest(1.1)
    (True, False)
    """
    sha = hashlib.sha256()
    _feed(sha, value)
    return sha.hexdigest()[:12]


def _feed(sha, value) -> None:
    if dataclasses.is_dataclass(value) and not isinstance(value, type):
        sha.update(type(value).__name__.encode())
        for f in dataclasses.fields(value):
            sha.update(f.name.encode())
            _feed(sha, getattr(value, f.name))
    elif isinstance(value, np.ndarray):
        sha.update(f"{value.dtype}{value.shape}".encode())
        sha.update(np.ascontiguousarray(value).tobytes())
    elif isinstance(value, (list, tuple)):
        sha.update(f"[{len(value)}".encode())
        for item in value:
            _feed(sha, item)
    elif isinstance(value, dict):
        sha.update(f"{{{len(value)}".encode())
        for key in sorted(value, key=repr):
            _feed(sha, key)
            _feed(sha, value[key])
    else:
        sha.update(repr(value).encode())


class Journal:
    """``trials.jsonl`` open for appending; :meth:`append` writes a trial and flushes it to disk."""

    def __init__(self, path: Path):
        self.path = path
        self._file = open(path, "a", encoding="utf-8")  # noqa: SIM115 -- closed by close()

    @classmethod
    def start(cls, out, bench: Bench) -> Journal:
        """A new journal in the folder ``out`` (replacing any there), holding only the settings."""
        path = Path(out) / JOURNAL
        _replace(path, [{"bench": settings(bench)}])
        return cls(path)

    def append(self, result: BenchTrial) -> None:
        """Write one finished trial."""
        self._file.write(json.dumps(trial_to_dict(result)) + "\n")
        self._file.flush()
        os.fsync(self._file.fileno())

    def close(self) -> None:
        self._file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def resume(out, bench: Bench) -> tuple[Journal, tuple[BenchTrial, ...]]:
    """Reopen the journal in ``out``: the journal, and the trials it holds (a torn last line dropped).

    Raises
    ------
    SimulationError
        No journal in ``out``, one that is not a bench's, or one written by a
        bench with other settings (the message names the first that differs);
        nothing is written then.
    """
    path = Path(out) / JOURNAL
    if not path.is_file():
        raise SimulationError(f"{out}: nothing to resume, no {JOURNAL} (run the bench with --out {out} first)")
    try:
        text = path.read_text(encoding="utf-8")
    except UnicodeDecodeError as err:
        raise SimulationError(f"{path}: not a bench journal (not UTF-8 text: byte {err.start})") from None
    lines = text.split("\n")
    header = _parse(lines[0], path, 1)
    if not isinstance(header, dict) or not isinstance(header.get("bench"), dict):
        raise SimulationError(f"{path}: not a bench journal (its first line holds no bench settings)")
    _same_settings(header["bench"], settings(bench), out)
    complete = lines[1:-1]  # the last piece is '' after a final newline, or a torn line
    results = [_trial(_parse(line, path, k + 2), bench, f"{path}, line {k + 2}")
               for k, line in enumerate(complete) if line]
    ran = {(r.planner, r.record.object, r.trial) for r in results}
    if len(ran) != len(results):
        raise SimulationError(f"{path}: a trial appears twice")
    if lines[-1]:
        _replace(path, [header, *map(trial_to_dict, results)])
    return Journal(path), tuple(results)


def _parse(line: str, path: Path, number: int):
    try:
        return json.loads(line)
    except json.JSONDecodeError as err:
        raise SimulationError(f"{path}, line {number}: not JSON ({err.msg})") from None
    except (ValueError, RecursionError) as err:  # a number of more digits than Python reads, nesting too deep
        raise SimulationError(f"{path}, line {number}: not a trial ({str(err).split(';')[0]})") from None


def _trial(data, bench: Bench, where: str) -> BenchTrial:
    """The trial of a journal line, checked field by field and against the bench resumed (``where`` names the line)."""
    try:
        line = _TrialLine.model_validate(data)
    except ValidationError as err:
        first = err.errors()[0]
        field = ".".join(map(str, first["loc"])) or "the line"
        raise SimulationError(f"{where}: not a trial of this bench ({field}: {first['msg']})") from None
    if line.planner not in bench.planners or line.object not in {o.name for o in bench.objects} \
            or line.trial >= bench.trials:
        raise SimulationError(f"{where}: a trial this bench does not run ({line.planner} on {line.object}, trial "
                              f"{line.trial}): the journal is another bench's")
    return trial_from_dict(line.model_dump())


def _same_settings(old: dict, new: dict, out) -> None:
    for key, value in new.items():
        if old.get(key) != value:
            raise SimulationError(f"{out}: cannot resume, the bench there ran with other {_difference(key, old.get(key), value)}"
                                  f"; use the same settings or another --out")


def _difference(key: str, old, new) -> str:
    if isinstance(old, list) and isinstance(new, list):
        gone, added = [v for v in old if v not in new], [v for v in new if v not in old]
        if not gone and not added:
            return f"{key}: the same, in another order"
        said = [f"{', '.join(map(str, gone[:3]))} there, not here" if gone else "",
                f"{', '.join(map(str, added[:3]))} here, not there" if added else ""]
        return f"{key}: {'; '.join(filter(None, said))}"
    return f"{key}: {shown(old)} there, {shown(new)} here"


def _replace(path: Path, rows) -> None:
    """Write ``rows`` as JSON lines to ``path`` atomically (a temporary file renamed over it)."""
    temporary = path.with_name(f".{path.name}.tmp")
    with open(temporary, "w", encoding="utf-8") as file:
        file.writelines(json.dumps(row) + "\n" for row in rows)
        file.flush()
        os.fsync(file.fileno())
    os.replace(temporary, path)
