"""Checks of arguments and values, in one place, for every entry point of the library.

Each check takes the argument's ``name`` (as the caller's signature or file
field spells it), returns the value converted to its plain Python or numpy
type, and raises an :class:`~contourgrasp.errors.InputError` subclass (``error``,
by default :class:`InputError` itself) whose message names the argument and
says what was expected. Nothing here computes; pure checks only, so every
module of the pipeline may import it without reaching up the pipeline.

Examples
--------
>>> positive("xy_step", 0.01)
0.01
>>> positive("xy_step", "0.05")
Traceback (most recent call last):
...
contourgrasp.errors.InputError: xy_step must be a finite number, got '0.05'
"""

from __future__ import annotations

import dataclasses
import math
from inspect import Parameter, signature

import numpy as np

from .errors import InputError

_REAL = (int, float, np.integer, np.floating)
#: Characters of a refused value quoted in a message.
_SHOWN = 40


def shown(value) -> str:
    """``repr(value)`` for a message, cut to a readable length (a refused value may be a 5,000-digit integer)."""
    text = repr(value)
    return text if len(text) <= _SHOWN else f"{text[:_SHOWN - 12]}... ({len(text)} characters)"


def finite(name: str, value, *, error: type[InputError] = InputError) -> float:
    """``value`` as a float; refused unless a real, finite number (a bool is not a number; nor is an integer
    beyond float's range)."""
    try:
        ok = not isinstance(value, bool) and isinstance(value, _REAL) and math.isfinite(value)
    except OverflowError:
        ok = False
    if not ok:
        raise error(f"{name} must be a finite number, got {shown(value)}")
    return float(value)


def positive(name: str, value, *, error: type[InputError] = InputError) -> float:
    """A finite number > 0."""
    if finite(name, value, error=error) <= 0:
        raise error(f"{name} must be positive, got {shown(value)}")
    return float(value)


def non_negative(name: str, value, *, error: type[InputError] = InputError) -> float:
    """A finite number >= 0."""
    if finite(name, value, error=error) < 0:
        raise error(f"{name} must be a number >= 0, got {shown(value)}")
    return float(value)


def fraction(name: str, value, *, error: type[InputError] = InputError) -> float:
    """A finite number in [0, 1]."""
    value = finite(name, value, error=error)
    if not 0.0 <= value <= 1.0:
        raise error(f"{name} must be in [0, 1], got {value}")
    return value


def at_most(name: str, value: float, limit: float, unit: str = "", *, error: type[InputError] = InputError) -> float:
    """``value`` (already a number) refused above ``limit``, the bound on the work an input may ask for."""
    if value > limit:
        raise error(f"{name} must be at most {limit:g}{unit}, got {value:g}{unit}")
    return value


def integer(name: str, value, minimum: int | None = None, *, maximum: int | None = None, odd: bool = False,
            error: type[InputError] = InputError) -> int:
    """An integer (not a bool) in [minimum, maximum]; ``odd`` refuses even ones."""
    bad = isinstance(value, bool) or not isinstance(value, (int, np.integer))
    if bad or (minimum is not None and value < minimum):
        bound = "" if minimum is None else f" >= {minimum}"
        raise error(f"{name} must be an integer{bound}, got {shown(value)}")
    if maximum is not None and value > maximum:
        raise error(f"{name} must be at most {maximum}, got {shown(value)}")
    if odd and value % 2 == 0:
        raise error(f"{name} must be odd, got {value}")
    return int(value)


def choice(name: str, value, choices, *, error: type[InputError] = InputError):
    """One of ``choices`` (compared with ==, so a string is never taken for a number; numpy's bool is a bool).

    >>> choice("slice_contour", np.bool_(True), (False, True, "unbalanced"))
    True
    """
    value = bool(value) if isinstance(value, np.bool_) else value
    if not any(type(value) is type(c) and value == c for c in choices):
        raise error(f"{name} must be one of {', '.join(map(repr, choices))}, got {shown(value)}")
    return value


def flag(name: str, value, *, error: type[InputError] = InputError) -> bool:
    """A bool (numpy's too); 0, 1 and strings are refused."""
    if not isinstance(value, (bool, np.bool_)):
        raise error(f"{name} must be True or False, got {shown(value)}")
    return bool(value)


def float_array(name: str, value, *, error: type[InputError] = InputError) -> np.ndarray:
    """``value`` as a float array; complex, object or non-numeric input is refused, not cast."""
    try:
        array = np.asarray(value)
    except (TypeError, ValueError):
        raise error(f"{name} must be an array of numbers") from None
    if array.dtype.kind in "cOUSV" or array.dtype.kind not in "biuf":
        kind = "complex numbers" if array.dtype.kind == "c" else f"dtype {array.dtype}"
        raise error(f"{name} must be an array of real numbers, got {kind}")
    return array.astype(float, copy=False)


def finite_array(name: str, value, shape: tuple[int | None, ...] | None = None, *,
                 error: type[InputError] = InputError) -> np.ndarray:
    """A float array of ``shape`` (None: any length on that axis) whose entries are all finite."""
    array = float_array(name, value, error=error)
    if shape is not None and (array.ndim != len(shape)
                              or any(n is not None and n != m for n, m in zip(shape, array.shape))):
        wanted = "(" + ", ".join("n" if n is None else str(n) for n in shape) + ("," if len(shape) == 1 else "") + ")"
        raise error(f"{name} must be a {wanted} array, got shape {array.shape}")
    bad = ~np.isfinite(array)
    if bad.any():
        raise error(f"{name}{list(int(i) for i in np.argwhere(bad)[0])} is not finite")
    return array


def pixel_mask(name: str, value, *, error: type[InputError] = InputError) -> np.ndarray:
    """``value`` as a non-empty (H, W) bool mask: an array of 0 and 1 (or bools) with at least one pixel set."""
    array = value if isinstance(value, np.ndarray) and value.dtype == bool else finite_array(
        name, value, (None, None), error=error)
    if array.ndim != 2:
        raise error(f"{name} must be an (H, W) mask, got shape {array.shape}")
    if array.dtype != bool and not ((array == 0.0) | (array == 1.0)).all():
        raise error(f"{name} must be a mask of 0 and 1 (or bools)")
    if not array.any():
        raise error(f"{name} is empty: no pixel is set")
    return array.astype(bool)


def same_size(shape_a, shape_b, name_a: str = "rgb image", name_b: str = "depth image", *,
              error: type[InputError] = InputError) -> None:
    """Two images of the same width and height."""
    if tuple(shape_a[:2]) != tuple(shape_b[:2]):
        raise error(f"{name_a} is {shape_a[1]}x{shape_a[0]} but {name_b} is "
                    f"{shape_b[1]}x{shape_b[0]} (width x height)")


def keyword_defaults(function) -> dict:
    """The keyword-only options of ``function`` with their defaults."""
    return {p.name: p.default for p in signature(function).parameters.values() if p.kind is Parameter.KEYWORD_ONLY}


def options(name: str, value, function, *, error: type[InputError] = InputError) -> dict:
    """A dict of keyword options of ``function`` (None: none); unknown names are refused by name."""
    if value is None:
        return {}
    if not isinstance(value, dict):
        raise error(f"{name} must be a dict of keyword options, got {type(value).__name__}")
    allowed = list(keyword_defaults(function))
    unknown = sorted(set(value) - set(allowed), key=str)
    if unknown:
        raise error(f"{name}: unknown option {unknown[0]!r}; choose from {', '.join(allowed)}")
    return dict(value)


def option_paths(options_type) -> dict[str, tuple[str, ...]]:
    """Every option of a frozen options dataclass by its flat name: name -> the path of fields to it.

    A field whose default is itself a dataclass is a group, walked in turn; its options are named by
    their own field names, which are unique across the groups (a planner file's keys, a CLI flag's).
    """
    paths = {}
    for f in dataclasses.fields(options_type):
        if dataclasses.is_dataclass(f.default):
            paths |= {name: (f.name, *path) for name, path in option_paths(type(f.default)).items()}
        else:
            paths[f.name] = (f.name,)
    return paths


def flat_options(options) -> dict:
    """The options of a frozen options dataclass (groups included) by flat name, in field order."""
    values = {}
    for name, path in option_paths(type(options)).items():
        value = options
        for field_name in path:
            value = getattr(value, field_name)
        values[name] = value
    return values


def with_options(options, values: dict, *, what: str, error: type[InputError] = InputError):
    """``options`` (a frozen options dataclass) with the flat-named ``values`` put in; each group changed is
    built anew, so its own checks run. A name no option has is refused by name, listing the options."""
    paths = option_paths(type(options))
    unknown = [name for name in values if name not in paths]
    if unknown:
        raise error(f"{what}: unknown option {unknown[0]!r}; choose from {', '.join(paths)}")
    grouped: dict[str, dict] = {}
    for name, value in values.items():
        head, *rest = paths[name]
        grouped.setdefault(head, {})
        if rest:
            grouped[head][name] = value
        else:
            grouped[head] = value
    changed = {head: with_options(getattr(options, head), value, what=what, error=error)
               if dataclasses.is_dataclass(getattr(options, head)) else value for head, value in grouped.items()}
    return dataclasses.replace(options, **changed) if changed else options


# --- perception ---


def depth_range(name: str, value, *, error: type[InputError] = InputError) -> tuple[float, float]:
    """Two finite numbers (near, far), meters, with 0 <= near < far."""
    try:
        lo, hi = (finite(name, v, error=error) for v in value)
    except (TypeError, ValueError):
        raise error(f"{name} must be two numbers (near, far) in meters, got {shown(value)}") from None
    if not 0 <= lo < hi:
        raise error(f"{name} must satisfy 0 <= near < far, got ({lo}, {hi})")
    return lo, hi


def integers(name: str, value, fields: str, *, error: type[InputError] = InputError) -> tuple[int, ...]:
    """As many integers (no bools) as ``fields`` names, e.g. ``"u, v"`` or ``"x, y, w, h"``; a tuple, list or array."""
    n = len(fields.split(","))
    values = np.asarray(value, dtype=object) if isinstance(value, (tuple, list, np.ndarray)) else None
    if values is None or values.shape != (n,) or not all(
            isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in values):
        count = {2: "two", 3: "three", 4: "four"}.get(n, str(n))
        raise error(f"{name} must be {count} integers ({fields}), got {shown(value)}")
    return tuple(int(v) for v in values)


def pixel_offset(name: str, value, *, error: type[InputError] = InputError) -> tuple[int, int]:
    """Two integers (dx, dy), pixels."""
    return integers(name, value, "dx, dy", error=error)


def pixel_contour(name: str, value, shape, *, error: type[InputError] = InputError) -> np.ndarray:
    """An (n, 2) float array of at least 3 finite pixels (u, v) inside an image of ``shape`` (H, W, ...)."""
    points = float_array(name, value, error=error)
    if points.ndim != 2 or points.shape[1] != 2 or len(points) < 3:
        raise error(f"{name} must be an (n, 2) array of at least 3 pixels (u, v), got shape {points.shape}")
    if not np.all(np.isfinite(points)):
        raise error(f"{name} point {int(np.flatnonzero(~np.all(np.isfinite(points), axis=1))[0])} is not finite")
    outside = ((points[:, 0] < -0.5) | (points[:, 0] > shape[1] - 0.5)
               | (points[:, 1] < -0.5) | (points[:, 1] > shape[0] - 0.5))
    if outside.any():
        i = int(np.flatnonzero(outside)[0])
        raise error(f"{name} point {i} {tuple(points[i])} is outside the {shape[1]}x{shape[0]} image")
    return points


def rigid_transform(name: str, value, *, rotation_tolerance: float, row_tolerance: float,
                    error: type[InputError] = InputError) -> np.ndarray:
    """A finite (4, 4) rigid transform: last row 0 0 0 1, rotation orthonormal with det +1 (within the tolerances).

    Returned as given (as a float array); nothing is re-orthonormalised here.
    """
    matrix = finite_array(name, value, (4, 4), error=error)
    if np.abs(matrix[3] - [0.0, 0.0, 0.0, 1.0]).max() > row_tolerance:
        raise error(f"{name}: the last row of a rigid transform must be 0 0 0 1, got {matrix[3].tolist()}")
    rotation = matrix[:3, :3]
    deviation = float(np.abs(rotation.T @ rotation - np.eye(3)).max())
    det = float(np.linalg.det(rotation))
    if not (deviation <= rotation_tolerance and abs(det - 1) <= rotation_tolerance):
        raise error(f"{name}: the rotation is not orthonormal with det +1 (|R^T R - I| = {deviation:.2e}, "
                    f"det = {det:.6f}; tolerance {rotation_tolerance:g})")
    return matrix


# --- synthesis ---


def bounded(name: str, value, limit: float, unit: str = "", *, strict: bool = False,
            error: type[InputError] = InputError) -> float:
    """A finite number >= 0 (> 0 if ``strict``) and at most ``limit``."""
    value = (positive if strict else non_negative)(name, value, error=error)
    return at_most(name, value, limit, unit, error=error)


def friction(name: str, value, limit: float, *, error: type[InputError] = InputError) -> float:
    """A Coulomb friction coefficient: a finite number in [0, ``limit``] (``tolerances.MAX_FRICTION``)."""
    value = non_negative(name, value, error=error)
    if value > limit:
        raise error(f"{name} must be a friction coefficient of at most {limit:g}, got {value:g}")
    return value
