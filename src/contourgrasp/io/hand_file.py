"""Hand description files (TOML) and the built-in presets.

Schema (all lengths in meters, angles in radians)::

    name = "my-hand"                 # required
    description = "..."              # optional
    min_touching = 4                 # required, 1..number of fingers
    miss_penalty = 250.0             # optional, >= 0, cost per finger closing on air;
                                     # default 10 x the largest alpha (about one finger's
                                     # swing of paper-curvature cost, |C| <~ 5 m)
    max_imbalance = 0.25             # optional, 0..1: the squeeze's balance the hand is planned
                                     # with by a planner asking for the hand's (default's
                                     # max_imbalance = "hand"); default 0.25; 1: off
    tips_brush_table = true          # optional, 3-D hands: the planned grasp height ("auto")
                                     # asks for the open fingertips just above the table, a
                                     # finger swinging lower as it closes may brush it;
                                     # default false: no closing fingertip reaches it
    grasp_height_fraction = 0.4      # optional, 3-D hands, 0..0.7: the least grasp height ("auto")
                                     # as a fraction of the object's height; default 0.4
    slice_contour = "unbalanced"     # optional, 3-D hands: the outline planned on by a planner
                                     # asking for the hand's (default's slice_contour = "hand"):
                                     # "unbalanced" (default) the cross-section at the grasp height
                                     # where the outline seen has no balanced squeeze; false the
                                     # outline seen; true the cross-section

    [[fingers]]                      # one table per finger, at least one
    name = "thumb"
    start = [-0.115, 0.1]            # (x_f, y_f), hand frame
    closing_direction = [0.994, 0.106]   # a ray ...
    # arc = { a_cos = 0.055, a_sin = 0.04, phi_off = 3.77 }   # ... or an elliptic arc
                                     # (counter-clockwise; a negative a_sin: clockwise)
    travel = 0.09                    # F > 0: distance (arc length for arcs)
    virtual_start = 0.03             # lambda_virt, optional, default 0
    alpha = 25.0                     # curvature gain, optional, default 1
    beta = 10000.0                   # ratio gain, optional, default 0
    required = true                  # optional, default false
    radius = 0.011                   # optional, >= 0, default 0: half the finger's
                                     # width (finger-thickness check of the planner;
                                     # the links' radius of its chain)

    [fingers.chain]                  # optional: the finger's body (3-D hand frame, z down)
    knuckle = [-0.088, 0.094]        # (x, y) of the proximal joint
    knuckle_depth = 0.0              # >= 0, below the palm's underside
    direction = [0.994, 0.106]       # optional: the chain's plane; default closing_direction
                                     # (required for an arc finger)
    links = [0.0668, 0.0547]         # proximal, distal > 0
    open_angles = [-0.43, 0.0]       # (q1, q2) of the open finger, rad
    closed_angles = [0.103, 0.533]   # and of the fully closed one (linear synergy between)
    # joints = [[[x, y, z], ...], ...]   # ... or, instead of those five keys, the chain as
                                     # measured (hand-from-model): per closing progress evenly
                                     # in [0, 1], its points from knuckle to tip (SampledChain)

    [palm]                           # with the chains: every finger has one, or none does
    outline = [[x, y], ...]          # >= 3 vertices, the palm's underside at z = 0, or
                                     # [[x, y, z], ...] on one plane: a tilted underside
    thickness = 0.025                # > 0

A 3-D part inconsistent with the 2-D one (the chain's open tip more than 1 mm from ``start``
on the palm plane, its closed tip more than 1 mm from the end of the travel, or its tip path
more than 1 mm off the ray or arc: :func:`contourgrasp.hand.check_chain`; 3 mm for a measured
chain, the fit tolerance of ``hand-from-model``) is refused naming the finger.

Lengths are at most ``tolerances.MAX_HAND_SIZE`` (2 m) in magnitude, ``|phi_off|`` at most
``tolerances.MAX_ARC_ANGLE``, gains (alpha, beta, miss_penalty) at most ``tolerances.MAX_GAIN``
and a hand has at most ``tolerances.MAX_FINGERS`` fingers. Unknown keys, wrong types and
impossible values are refused with :class:`~contourgrasp.errors.HandFileError` naming the file
and the field; so is a file that is not UTF-8 text or TOML.
"""

from __future__ import annotations

import json
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from .. import tolerances as tol
from ..errors import HandError, HandFileError
from ..hand import Arc, Finger, FingerChain, Hand, Palm, Ray, SampledChain, check_chain
from . import _toml_files

_PRESET_DIR = "data/hands"

#: Default miss_penalty per unit of the largest curvature gain alpha.
MISS_PENALTY_PER_ALPHA = 10.0

FiniteFloat = Annotated[float, Field(allow_inf_nan=False)]
Length = Annotated[float, Field(gt=0, le=tol.MAX_HAND_SIZE, allow_inf_nan=False)]
Offset = Annotated[float, Field(ge=-tol.MAX_HAND_SIZE, le=tol.MAX_HAND_SIZE, allow_inf_nan=False)]
Radius = Annotated[float, Field(ge=0, le=tol.MAX_HAND_SIZE, allow_inf_nan=False)]
Gain = Annotated[float, Field(ge=0, le=tol.MAX_GAIN, allow_inf_nan=False)]
Angle = Annotated[float, Field(ge=-tol.MAX_ARC_ANGLE, le=tol.MAX_ARC_ANGLE, allow_inf_nan=False)]
Point2 = Annotated[list[Offset], Field(min_length=2, max_length=2)]
Vector2 = Annotated[list[FiniteFloat], Field(min_length=2, max_length=2)]


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, frozen=True)


class _ArcSchema(_Strict):
    a_cos: Length
    a_sin: Offset
    phi_off: Angle

    @field_validator("a_sin")
    @classmethod
    def _not_zero(cls, value: float) -> float:
        if value == 0:
            raise ValueError("must not be 0 (negative: an arc turning clockwise)")
        return value


Angles2 = Annotated[list[Annotated[float, Field(ge=-tol.MAX_JOINT_ANGLE, le=tol.MAX_JOINT_ANGLE,
                                                 allow_inf_nan=False)]], Field(min_length=2, max_length=2)]
Links2 = Annotated[list[Length], Field(min_length=2, max_length=2)]
Point3 = Annotated[list[Offset], Field(min_length=3, max_length=3)]
Samples = Annotated[list[Annotated[list[Point3], Field(min_length=2, max_length=tol.MAX_CHAIN_POINTS)]],
                    Field(min_length=2, max_length=tol.MAX_CHAIN_SAMPLES)]


class _ChainSchema(_Strict):
    knuckle: Point2 | None = None
    knuckle_depth: Radius | None = None
    direction: Vector2 | None = None
    links: Links2 | None = None
    open_angles: Angles2 | None = None
    closed_angles: Angles2 | None = None
    joints: Samples | None = None

    @model_validator(mode="after")
    def _one_form(self):
        planar = ("knuckle", "knuckle_depth", "links", "open_angles", "closed_angles")
        given = [k for k in planar if getattr(self, k) is not None]
        if self.joints is not None:
            if given or self.direction is not None:
                raise ValueError(f"give either joints (a measured chain) or the planar chain's keys, not both "
                                 f"(got joints and {', '.join(given or ['direction'])})")
            if len({len(sample) for sample in self.joints}) != 1:
                raise ValueError("every sample of joints must have the same number of points")
            return self
        if missing := [k for k in planar if k not in given]:
            raise ValueError(f"a planar chain needs {', '.join(planar)}; missing: {', '.join(missing)} "
                             "(or give joints, a measured chain)")
        if self.direction is not None and max(map(abs, self.direction)) == 0:
            raise ValueError("direction has zero length")
        return self


class _PalmSchema(_Strict):
    outline: Annotated[list[Annotated[list[Offset], Field(min_length=2, max_length=3)]], Field(min_length=3,
                                                                                               max_length=1000)]
    thickness: Length


class _FingerSchema(_Strict):
    name: str = Field(min_length=1)
    start: Point2
    closing_direction: Vector2 | None = None
    arc: _ArcSchema | None = None
    travel: Length
    virtual_start: Offset = 0.0
    alpha: Annotated[float, Field(ge=-tol.MAX_GAIN, le=tol.MAX_GAIN, allow_inf_nan=False)] = 1.0
    beta: Gain = 0.0
    required: bool = False
    radius: Radius = 0.0
    chain: _ChainSchema | None = None

    @model_validator(mode="after")
    def _one_trajectory(self):
        if (self.closing_direction is None) == (self.arc is None):
            raise ValueError("give exactly one of closing_direction (a ray) or arc")
        if self.closing_direction is not None and max(map(abs, self.closing_direction)) == 0:
            raise ValueError("closing_direction has zero length")
        if self.chain is not None and self.chain.joints is None and self.chain.direction is None and self.arc is not None:
            raise ValueError("chain.direction is required for a finger on an arc")
        return self


class _HandSchema(_Strict):
    name: str = Field(min_length=1)
    description: str = ""
    min_touching: int = Field(ge=1)
    miss_penalty: Gain | None = None
    max_imbalance: Annotated[float, Field(ge=0, le=1, allow_inf_nan=False)] = tol.HAND_MAX_IMBALANCE
    tips_brush_table: bool = False
    grasp_height_fraction: Annotated[float, Field(ge=0, le=tol.MAX_GRASP_HEIGHT_FRACTION,
                                                  allow_inf_nan=False)] = tol.GRASP_HEIGHT_FRACTION
    slice_contour: bool | Literal["unbalanced"] = "unbalanced"
    fingers: list[_FingerSchema] = Field(min_length=1, max_length=tol.MAX_FINGERS)
    palm: _PalmSchema | None = None

    @field_validator("slice_contour", mode="before")
    @classmethod
    def _slice(cls, value):
        return _toml_files.flag_or_word(value, ("unbalanced",))

    @model_validator(mode="after")
    def _consistent(self):
        if self.min_touching > len(self.fingers):
            raise ValueError(f"min_touching = {self.min_touching} exceeds the {len(self.fingers)} fingers")
        names = [f.name for f in self.fingers]
        if len(set(names)) != len(names):
            raise ValueError(f"finger names must be unique, got {names}")
        without = [f.name for f in self.fingers if f.chain is None]
        if (self.palm is not None or len(without) < len(self.fingers)) and (without or self.palm is None):
            missing = f"[fingers.chain] of {', '.join(without)}" if without else "[palm]"
            raise ValueError(f"a 3-D hand needs a [fingers.chain] for every finger and a [palm]; missing: {missing}")
        return self


def preset_names() -> list[str]:
    """Names of the built-in hands, sorted."""
    return _toml_files.preset_names(_PRESET_DIR)


def load_hand(spec) -> Hand:
    """A hand from a preset name, a TOML file path, or a :class:`Hand` (returned as is).

    Examples
    --------
    >>> load_hand("three-finger").min_touching
    3
    """
    if isinstance(spec, Hand):
        return spec
    text, source = _toml_files.read_spec(str(spec), _PRESET_DIR, kind="hand", error=HandFileError)
    return parse_hand(text, source=source)


def parse_hand(text: str, *, source: str = "<string>") -> Hand:
    """Parse and validate the TOML text of a hand description; ``source`` names it in errors."""
    raw = _toml_files.parse_toml(text, source, error=HandFileError)
    try:
        schema = _HandSchema.model_validate(raw)
    except ValidationError as err:
        raise HandFileError(f"{source}: {_describe(err, raw)}") from None
    try:
        fingers = tuple(_finger(f) for f in schema.fingers)
    except HandError as err:
        raise HandFileError(f"{source}: {err}") from None
    chains = palm = None
    if schema.palm is not None:
        chains = tuple(_chain(source, i, f, s) for i, (f, s) in enumerate(zip(fingers, schema.fingers, strict=True)))
        try:
            palm = Palm(outline=tuple(map(tuple, schema.palm.outline)), thickness=schema.palm.thickness)
        except HandError as err:
            raise HandFileError(f"{source}: palm: {err}") from None
    try:
        return Hand(
            name=schema.name,
            fingers=fingers,
            min_touching=schema.min_touching,
            miss_penalty=_miss_penalty(schema),
            max_imbalance=schema.max_imbalance,
            tips_brush_table=schema.tips_brush_table,
            grasp_height_fraction=schema.grasp_height_fraction,
            slice_contour=schema.slice_contour,
            description=schema.description,
            chains=chains,
            palm=palm,
        )
    except HandError as err:
        raise HandFileError(f"{source}: {err}") from None


def _chain(source: str, index: int, finger: Finger, f: _FingerSchema) -> FingerChain | SampledChain:
    """The chain of ``finger``, checked against its trajectory; errors name ``fingers[index] (name).chain``."""
    c = f.chain
    try:
        if c.joints is not None:
            chain = SampledChain(joints=c.joints, radius=finger.radius)
        else:
            direction = c.direction if c.direction is not None else finger.trajectory.closing_direction
            chain = FingerChain(knuckle=tuple(c.knuckle), knuckle_depth=c.knuckle_depth, direction=tuple(direction),
                                links=tuple(c.links), radius=finger.radius, open_angles=tuple(c.open_angles),
                                closed_angles=tuple(c.closed_angles))
        check_chain(finger, chain)
    except HandError as err:
        raise HandFileError(f"{source}: fingers[{index}] ({finger.name}).chain: {err}") from None
    return chain


def _miss_penalty(schema: _HandSchema) -> float:
    if schema.miss_penalty is not None:
        return schema.miss_penalty
    return MISS_PENALTY_PER_ALPHA * max(abs(f.alpha) for f in schema.fingers)


def _finger(f: _FingerSchema) -> Finger:
    trajectory = Ray(tuple(f.closing_direction)) if f.arc is None else Arc(f.arc.a_cos, f.arc.a_sin, f.arc.phi_off)
    return Finger(
        name=f.name,
        start=tuple(f.start),
        trajectory=trajectory,
        travel=f.travel,
        virtual_start=f.virtual_start,
        alpha=f.alpha,
        beta=f.beta,
        required=f.required,
        radius=f.radius,
    )


def _describe(err: ValidationError, raw: dict) -> str:
    """The first validation error as 'fingers[0] (thumb).travel: message'."""
    first = err.errors()[0]
    parts = []
    for key in first["loc"]:
        if isinstance(key, int) and parts:
            name = _finger_name(raw, key) if parts[-1] == "fingers" else None
            parts[-1] += f"[{key}]" + (f" ({name})" if name else "")
        else:
            parts.append(str(key))
    field = ".".join(parts) or "hand"
    message = first["msg"]
    if first["type"] == "extra_forbidden":
        message = "unknown key"
    elif first["type"] == "missing":
        message = "required field is missing"
    return f"{field}: {message.removeprefix('Value error, ')}"


def _finger_name(raw: dict, index: int) -> str | None:
    try:
        name = raw["fingers"][index]["name"]
    except (KeyError, IndexError, TypeError):
        return None
    return name if isinstance(name, str) else None


def hand_to_toml(hand: Hand, *, comment: str = "") -> str:
    """The text of a hand file that loads back as ``hand``, ``comment`` as its header."""
    lines = [f"# {line}".rstrip() for line in comment.splitlines()]
    lines += [f"name = {_string(hand.name)}", f"description = {_string(hand.description)}",
              f"min_touching = {hand.min_touching}", f"miss_penalty = {_float(hand.miss_penalty)}",
              f"max_imbalance = {_float(hand.max_imbalance)}",
              f"tips_brush_table = {'true' if hand.tips_brush_table else 'false'}"]
    if hand.grasp_height_fraction != tol.GRASP_HEIGHT_FRACTION:  # written where it differs: absent reads as the default
        lines.append(f"grasp_height_fraction = {_float(hand.grasp_height_fraction)}")
    if hand.slice_contour != "unbalanced":
        lines.append(f"slice_contour = {str(hand.slice_contour).lower()}")
    for f in hand.fingers:
        lines += ["", "[[fingers]]", f"name = {_string(f.name)}", f"start = {_floats(f.start)}"]
        if isinstance(f.trajectory, Ray):
            lines.append(f"closing_direction = {_floats(f.trajectory.closing_direction)}")
        else:
            arc = f.trajectory
            lines.append(f"arc = {{ a_cos = {_float(arc.a_cos)}, a_sin = {_float(arc.a_sin)}, "
                         f"phi_off = {_float(arc.phi_off)} }}")
        lines += [f"travel = {_float(f.travel)}", f"virtual_start = {_float(f.virtual_start)}",
                  f"alpha = {_float(f.alpha)}", f"beta = {_float(f.beta)}", f"required = {str(f.required).lower()}",
                  f"radius = {_float(f.radius)}"]
        if hand.chains is not None:
            lines += chain_toml(hand.chains[hand.fingers.index(f)], f)
    if hand.palm is not None:
        lines += palm_toml(hand.palm)
    return "\n".join(lines) + "\n"


def chain_toml(chain: FingerChain | SampledChain, finger: Finger) -> list[str]:
    """The lines of the ``[fingers.chain]`` table of ``chain`` (a planar chain's direction only when not the ray's;
    a sampled chain's joints one sample a line)."""
    if isinstance(chain, SampledChain):
        samples = ",\n  ".join("[" + ", ".join(_floats(p) for p in sample) + "]" for sample in chain.joints)
        return ["", "[fingers.chain]", f"joints = [\n  {samples},\n]"]
    lines = ["", "[fingers.chain]", f"knuckle = {_floats(chain.knuckle)}",
             f"knuckle_depth = {_float(chain.knuckle_depth)}"]
    if not isinstance(finger.trajectory, Ray) or tuple(chain.direction) != finger.trajectory.closing_direction:
        lines.append(f"direction = {_floats(chain.direction)}")
    return lines + [f"links = {_floats(chain.links)}", f"open_angles = {_floats(chain.open_angles)}",
                    f"closed_angles = {_floats(chain.closed_angles)}"]


def palm_toml(palm: Palm) -> list[str]:
    """The lines of the ``[palm]`` table."""
    vertices = palm.outline if palm.depths is None else [(*p, z) for p, z in zip(palm.outline, palm.depths, strict=True)]
    outline = ", ".join(_floats(p) for p in vertices)
    return ["", "[palm]", f"outline = [{outline}]", f"thickness = {_float(palm.thickness)}"]


def _string(text: str) -> str:
    # JSON's escapes are TOML's; TOML also refuses a raw DEL, which JSON leaves alone.
    return json.dumps(text, ensure_ascii=False).replace("\x7f", "\\u007f")


def _float(value) -> str:
    return repr(float(value))  # shortest text that reads back as the same float; TOML parses it


def _floats(values) -> str:
    return "[" + ", ".join(map(_float, values)) + "]"
