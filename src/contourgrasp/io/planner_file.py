"""Planner files (TOML): named :class:`~contourgrasp.pipeline.PlanOptions`, and the presets.

A planner is the part of a plan that is not the hand: how the contour is
modelled, how finely poses are searched, which safeguards apply. ``paper``
reproduces the thesis; ``default`` is the best the simulated bench has shown
(docs/bench.md, "Simulated grasping experiment"). Schema (SI units, angles in radians;
every key but ``name`` optional, a missing key takes the function's default,
which is the thesis's setting)::

    name = "my-planner"
    description = "..."
    harmonics = 4                # EFD harmonics, or "adaptive" (contour.choose_harmonics)
    curvature = "paper"          # or "geometric"
    xy_step = 0.05               # grid step in x and y, m (Table 4.1)
    yaw_step = 0.0349066         # grid step in yaw, rad (2 deg)
    d_max = 0.15                 # or [x, y], m (Table 4.2)
    d_min = 0.015                # m (Table 4.2)
    depth_mode = "max"           # or "plane" (perception.contour_to_metric)
    footprint = true             # plan the object's footprint (perception.object_footprint); absent:
                                 # only when the camera is tilted more than 2 deg
    refine = false               # continuous refinement of the best grid poses
    finger_thickness = false     # synthesis.Safeguards ...
    clearance = 0.0              # m
    friction = 0.5
    require_closure = false
    quality_gain = 0.0
    centring_gain = 0.0          # prefer poses with the object between thumb and index (Safeguards)
    max_imbalance = 1.0          # prefer poses whose equal finger pushes leave at most this share of net force
                                 # (1: off), or "hand": the hand file's own (Hand.max_imbalance)
    descent = false              # the open 3-D hand's descent onto the height map (synthesis.Descent)
    grasp_height = "clearance"   # or "auto", or a height in m (synthesis.grasp_height)
    slice_contour = false        # plan on the cross-section at the grasp height (perception.cross_section);
                                 # "unbalanced": only where the outline seen has no balanced squeeze;
                                 # "hand": the hand file's own (Hand.slice_contour)
    closing_sweep = false        # refuse poses where a finger's link meets the object before its tip (synthesis.sweep)
    closing_obstacles = false    # refuse poses where a closing finger runs into a neighbour or a bin wall
    small_objects = false        # fewer touching fingers where no pose satisfies the constraints (synthesis.search)
    low_objects = false          # an object lower than tolerances.LOW_OBJECT_HEIGHT planned first as a pinch (plan_frame)
    approaches = "top"           # approach kinds chosen among, joined by "+": top, side, tilted (pipeline.approach_set)

Unknown keys, wrong types and impossible values are refused with
:class:`PlannerFileError` naming the file and the field; so is a file that is not UTF-8 text or
TOML. The bounds are the search's (:mod:`contourgrasp.tolerances`): harmonics at most
``MAX_HARMONICS``, lengths at most ``MAX_SEARCH_LENGTH``, friction at most ``MAX_FRICTION``, ``centring_gain`` at
most ``MAX_CENTRING_GAIN``, and
a grid of at most ``MAX_GRID_POSES`` poses.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator, model_validator

from .. import tolerances as tol
from ..errors import PlannerError, PlannerFileError
from ..validation import with_options

if TYPE_CHECKING:
    from ..pipeline import PlanOptions
from . import _toml_files

_PRESET_DIR = "data/planners"

Positive = Annotated[float, Field(gt=0, le=tol.MAX_SEARCH_LENGTH, allow_inf_nan=False)]
Distance = Annotated[float, Field(ge=0, le=tol.MAX_SEARCH_LENGTH, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]


class _PlannerSchema(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, frozen=True)

    name: str = Field(min_length=1)
    description: str = ""
    harmonics: Annotated[int, Field(ge=1, le=tol.MAX_HARMONICS)] | Literal["adaptive"] | None = None
    curvature: Literal["paper", "geometric"] | None = None
    xy_step: Positive | None = None
    yaw_step: Annotated[float, Field(gt=0, le=6.283185307179586, allow_inf_nan=False)] | None = None
    d_max: Distance | Annotated[list[Distance], Field(min_length=2, max_length=2)] | None = None
    d_min: Distance | None = None
    depth_mode: Literal["max", "plane"] | None = None
    footprint: bool | None = None
    refine: bool | None = None
    finger_thickness: bool | None = None
    clearance: Distance | None = None
    friction: Annotated[float, Field(ge=0, le=tol.MAX_FRICTION, allow_inf_nan=False)] | None = None
    require_closure: bool | None = None
    quality_gain: NonNegative | None = None
    centring_gain: Annotated[float, Field(ge=0, le=tol.MAX_CENTRING_GAIN, allow_inf_nan=False)] | None = None
    max_imbalance: Literal["hand"] | Annotated[float, Field(ge=0, le=1, allow_inf_nan=False)] | None = None
    descent: bool | None = None
    slice_contour: bool | Literal["unbalanced", "hand"] | None = None
    closing_sweep: bool | None = None
    closing_obstacles: bool | None = None
    small_objects: bool | None = None
    low_objects: bool | None = None
    approaches: str | None = None
    grasp_height: (Literal["clearance", "auto"]
                   | Annotated[float, Field(ge=0, le=tol.MAX_HAND_SIZE, allow_inf_nan=False)] | None) = None

    @field_validator("slice_contour", mode="before")
    @classmethod
    def _slice(cls, value):
        return _toml_files.flag_or_word(value, ("unbalanced", "hand"))

    @field_validator("approaches")
    @classmethod
    def _approaches(cls, value):
        """Kinds joined by ``+``, each once: the search's own check, so that the refusal names the file."""
        from ..synthesis.options import check_approaches

        try:
            return check_approaches(value)
        except PlannerError as err:
            raise ValueError(str(err)) from None

    @field_validator("grasp_height", mode="before")
    @classmethod
    def _height(cls, value):
        """A number is a height: say so when it is out of range, rather than that it is no rule's name."""
        if isinstance(value, (int, float)) and not isinstance(value, bool) and not 0 <= value <= tol.MAX_HAND_SIZE:
            raise ValueError(f"a grasp height must be in [0, {tol.MAX_HAND_SIZE:g}] m, got {value!r}")
        return float(value) if isinstance(value, int) and not isinstance(value, bool) else value

    @model_validator(mode="after")
    def _grid_size(self):
        """The grid's own checks (its size above all), with the search's defaults for what is unset."""
        grid = {k: getattr(self, k) for k in ("xy_step", "yaw_step", "d_max", "d_min") if getattr(self, k) is not None}
        try:
            from ..synthesis import SearchGrid

            SearchGrid(**grid)
        except PlannerError as err:
            raise ValueError(str(err)) from None
        return self


@dataclass(frozen=True)
class Planner:
    """A named set of :class:`~contourgrasp.pipeline.PlanOptions`.

    Attributes
    ----------
    name : str
    description : str
    settings : tuple of (str, value)
        The options the file sets, by flat name in schema order (``d_max`` as a tuple).
    options : PlanOptions
        Every option: the file's settings over the defaults, built once (:meth:`from_settings`).
    """

    name: str
    description: str
    settings: tuple[tuple[str, object], ...]
    options: PlanOptions

    @classmethod
    def from_settings(cls, name: str, description: str, settings) -> Planner:
        """The planner setting ``settings`` ((flat name, value) pairs) over the defaults; PlannerError naming a bad one."""
        from ..pipeline import PlanOptions  # the pipeline's import cost only where a planner is loaded

        settings = tuple(settings)
        return cls(name, description, settings,
                   with_options(PlanOptions(), dict(settings), what=f"planner {name!r}", error=PlannerError))


def planner_names() -> list[str]:
    """Names of the built-in planners, sorted."""
    return _toml_files.preset_names(_PRESET_DIR)


def load_planner(spec) -> Planner:
    """A planner from a preset name, a TOML file path, or a :class:`Planner` (returned as is).

    Examples
    --------
    >>> load_planner("paper").options.search.harmonics
    4
    """
    if isinstance(spec, Planner):
        return spec
    text, source = _toml_files.read_spec(str(spec), _PRESET_DIR, kind="planner", error=PlannerFileError)
    return parse_planner(text, source=source)


def parse_planner(text: str, *, source: str = "<string>") -> Planner:
    """Parse and validate the TOML text of a planner; ``source`` names it in errors."""
    raw = _toml_files.parse_toml(text, source, error=PlannerFileError)
    try:
        schema = _PlannerSchema.model_validate(raw)
    except ValidationError as err:
        raise PlannerFileError(f"{source}: {_describe(err)}") from None
    options = []
    for key in _PlannerSchema.model_fields:
        value = getattr(schema, key)
        if key in ("name", "description") or value is None:
            continue
        options.append((key, tuple(value) if isinstance(value, list) else value))
    return Planner.from_settings(schema.name, schema.description, options)


def _describe(err: ValidationError) -> str:
    """The first validation error as 'field: message'."""
    first = err.errors()[0]
    if not first["loc"]:  # the whole planner, e.g. a grid too large
        return first["msg"].removeprefix("Value error, ")
    field = str(first["loc"][0])
    if first["type"] == "extra_forbidden":
        return f"{field}: unknown key"
    if first["type"] == "missing":
        return f"{field}: required field is missing"
    return f"{field}: {first['msg'].removeprefix('Value error, ')}"
