"""Planner files (TOML): named settings of :func:`contourgrasp.pipeline.plan_grasp`, and the presets.

A planner is the part of a plan that is not the hand: how the contour is
modelled, how finely poses are searched, which safeguards apply. ``paper``
reproduces the thesis; ``default`` is the best the simulated bench has shown
(README, "Simulated grasping experiment"). Schema (SI units, angles in radians;
every key but ``name`` optional, a missing key takes the function's default,
which is the thesis's setting)::

    name = "my-planner"
    description = "..."
    harmonics = 4                # EFD harmonics, or "adaptive" (efd.choose_harmonics)
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

Unknown keys, wrong types and impossible values are refused with
:class:`PlannerFileError` naming the file and the field.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from ..errors import InputError
from . import _toml_files

_PRESET_DIR = "data/planners"
#: Options that belong to perception (the rest are :func:`contourgrasp.synthesis.synthesize`'s).
PERCEPTION_OPTIONS = ("depth_mode", "footprint")

Positive = Annotated[float, Field(gt=0, allow_inf_nan=False)]
NonNegative = Annotated[float, Field(ge=0, allow_inf_nan=False)]


class PlannerFileError(InputError):
    """A planner file that cannot be read or does not follow the schema."""


class _PlannerSchema(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, frozen=True)

    name: str = Field(min_length=1)
    description: str = ""
    harmonics: Annotated[int, Field(ge=1)] | Literal["adaptive"] | None = None
    curvature: Literal["paper", "geometric"] | None = None
    xy_step: Positive | None = None
    yaw_step: Annotated[float, Field(gt=0, le=6.283185307179586, allow_inf_nan=False)] | None = None
    d_max: NonNegative | Annotated[list[NonNegative], Field(min_length=2, max_length=2)] | None = None
    d_min: NonNegative | None = None
    depth_mode: Literal["max", "plane"] | None = None
    footprint: bool | None = None
    refine: bool | None = None
    finger_thickness: bool | None = None
    clearance: NonNegative | None = None
    friction: NonNegative | None = None
    require_closure: bool | None = None
    quality_gain: NonNegative | None = None


@dataclass(frozen=True)
class Planner:
    """Named options of :func:`contourgrasp.pipeline.plan_grasp`.

    Attributes
    ----------
    name : str
    description : str
    options : tuple of (str, value)
        The options the file sets, in schema order (``d_max`` as a tuple).
    """

    name: str
    description: str
    options: tuple[tuple[str, object], ...]

    @property
    def plan_options(self) -> dict:
        """Keyword options of :func:`contourgrasp.pipeline.plan_grasp`."""
        return dict(self.options)

    @property
    def synthesis_options(self) -> dict:
        """Keyword options of :func:`contourgrasp.synthesis.synthesize` (perception's left out)."""
        return synthesis_options(dict(self.options))


def synthesis_options(options: dict) -> dict:
    """The options of :func:`contourgrasp.pipeline.plan_grasp` that :func:`contourgrasp.synthesis.synthesize` takes."""
    return {k: v for k, v in options.items() if k not in PERCEPTION_OPTIONS}


def planner_names() -> list[str]:
    """Names of the built-in planners, sorted."""
    return _toml_files.preset_names(_PRESET_DIR)


def load_planner(spec) -> Planner:
    """A planner from a preset name, a TOML file path, or a :class:`Planner` (returned as is).

    Examples
    --------
    >>> load_planner("paper").synthesis_options["harmonics"]
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
    return Planner(schema.name, schema.description, tuple(options))


def _describe(err: ValidationError) -> str:
    """The first validation error as 'field: message'."""
    first = err.errors()[0]
    field = str(first["loc"][0]) if first["loc"] else "planner"
    if first["type"] == "extra_forbidden":
        return f"{field}: unknown key"
    if first["type"] == "missing":
        return f"{field}: required field is missing"
    return f"{field}: {first['msg']}"
