"""Procedurally generated objects: a seeded training set the shapes of the YCB families.

:func:`procedural_object` builds one object from a seed: its family, then its sizes, its pose on
the table (standing or lying, where it stands stably), its material and colour, all drawn from
``numpy.random.default_rng(seed)``. The families are the shapes the YCB objects cover:

==============  =========================================================  ==========================
family          shape                                                      material (frictions)
==============  =========================================================  ==========================
``box``         3-20 cm boxes of any aspect ratio, standing or lying       cardboard or wood
``cylinder``    radius 1.5-5 cm, 4-25 cm long, standing or lying           tinplate or hard plastic
``bottle``      a body, a tapered shoulder, a neck and a cap, lying or     plastic bottle
                standing
``mug``         a thin-walled cylinder, its bottom and a handle            hard plastic or glass
``bowl``        a flared thin wall round a flat bottom                     hard plastic
``utensil``     a flat handle and a flat head (a spoon, a spatula)         steel or hard plastic
``tool``        a round handle and a head across its end (a hammer) or a   wood or steel
                thin shaft along it (a screwdriver)
``small``       a ball, a cube or an egg, 2-7 cm                           rubber, wood, plastic fruit
``stone``       a pebble of random outline (as the thesis's stones)        stone
==============  =========================================================  ==========================

Every part is convex (a box, cylinder, capsule, sphere or ellipsoid, or the hull of a mesh), so
MuJoCo collides the object as built; thin walls are rings of convex segments. The mass is the
parts' volume times the family's density (a hollow item's walls in solid plastic or glass; a box
or a bottle by its outline, as full), 20 g to 1 kg; frictions and the base colour are the material's
(:data:`~contourgrasp.sim.materials.MATERIALS`), the colour's shade varied by the seed.

Sets for ``--objects``: ``procedural:N`` is the training set, the seeds 0 to N - 1;
``procedural-test:N`` the held-out set, the seeds ``TEST_SEED`` to ``TEST_SEED`` + N - 1, reported
and never tuned on. One object is ``proc-<seed>``; its name says its family (``proc-7-mug``).
"""

from __future__ import annotations

import re

import numpy as np
from scipy.spatial import ConvexHull

from ..errors import SimulationError
from ..tolerances import MAX_PROCEDURAL_OBJECTS
from .objects import ObjectSpec, Part, _axis_to_x, _frustum, _pebble, _quat_matrix
from .materials import MATERIALS

#: The first seed of the held-out set ``procedural-test:N``.
TEST_SEED = 1_000_000
#: The families, in the order a seed picks among them (uniformly).
FAMILIES = ("box", "cylinder", "bottle", "mug", "bowl", "utensil", "tool", "small", "stone")
#: Densities (kg/m^3) of the parts as built, where not the material's: full bottles by their outline, solid walls
#: for mugs and bowls, thin metal or plastic utensils (a spoon, 30-60 g), a handle with a head (a hammer, 0.3 kg).
_DENSITY = {"bottle": 900.0, "mug": 1300.0, "bowl": 1050.0, "utensil": 3000.0, "tool": 1200.0}
#: Where a material's density here is not :data:`MATERIALS`' (of a hollow moulded part's outline): solid ABS.
_SOLID = {"hard-plastic": 1050.0}
_NAME = re.compile(r"proc-(\d+)(?:-([a-z]+))?$")
_SET = re.compile(r"(procedural|procedural-test):(\d+)$")


def procedural_object(seed: int) -> ObjectSpec:
    """The procedural object of ``seed`` (module docstring), named ``proc-<seed>-<family>``.

    Examples
    --------
    >>> a, b = procedural_object(7), procedural_object(7)
    >>> a.name == b.name and a.mass == b.mass
    True
    >>> round(float(a.points()[:, 2].min()), 9)  # resting on the table
    0.0
    """
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)) or seed < 0:
        raise SimulationError(f"a procedural object's seed must be a non-negative integer, got {seed!r}")
    rng = np.random.default_rng(int(seed))
    family = FAMILIES[int(rng.integers(len(FAMILIES)))]
    parts, material = _BUILDERS[family](rng)
    parts = _resting(parts)
    stuff = MATERIALS[material]
    density = _DENSITY.get(family, _SOLID.get(material, stuff.density))
    mass = float(np.clip(density * sum(_volume(p) for p in parts), 0.02, 1.0))
    return ObjectSpec(f"proc-{int(seed)}-{family}", parts, mass=mass, friction_hand=stuff.friction_hand,
                      friction_table=stuff.friction_table, rgba=_shade(stuff.rgba, rng))


def procedural_names(token: str) -> tuple[str, ...] | None:
    """The object names of a set token ``procedural:N`` or ``procedural-test:N``; None for any other token.

    Raises
    ------
    SimulationError
        N is 0 or more than ``MAX_PROCEDURAL_OBJECTS``.
    """
    found = _SET.match(token)
    if found is None:
        return None
    count = int(found.group(2))
    if not 1 <= count <= MAX_PROCEDURAL_OBJECTS:
        raise SimulationError(f"{token}: a procedural set holds 1 to {MAX_PROCEDURAL_OBJECTS} objects, got {count}")
    first = 0 if found.group(1) == "procedural" else TEST_SEED
    return tuple(f"proc-{s}" for s in range(first, first + count))


def procedural_family(name: str) -> str | None:
    """The family of a name ``proc-<seed>-<family>`` (:data:`FAMILIES`); None for any other name."""
    found = _NAME.match(name)
    family = None if found is None else found.group(2)
    return family if family in FAMILIES else None


def procedural_seed(name: str) -> int | None:
    """The seed of a name ``proc-<seed>`` (or ``proc-<seed>-<family>``); None for any other name."""
    found = _NAME.match(name)
    return None if found is None else int(found.group(1))


def _box(rng):
    sides = np.sort(rng.uniform([0.03, 0.03, 0.02], [0.20, 0.12, 0.15]))[::-1]
    lying = rng.random() < 0.5 or sides[1] < 0.45 * sides[0]  # a slim box does not stand
    height = sides[2] if lying else sides[0]
    plan = sides[:2] if lying else sides[1:]
    return (Part("box", (plan[0] / 2, plan[1] / 2, height / 2)),), str(rng.choice(["cardboard", "wood"]))


def _cylinder(rng):
    radius, length = rng.uniform(0.015, 0.05), rng.uniform(0.04, 0.25)
    standing = rng.random() < 0.5 and length < 5 * radius
    part = (Part("cylinder", (radius, length / 2)) if standing else
            Part("cylinder", (radius, length / 2), quat=_axis_to_x()))
    return (part,), str(rng.choice(["tinplate", "hard-plastic"]))


def _bottle(rng):
    r_body, body = rng.uniform(0.025, 0.045), rng.uniform(0.08, 0.20)
    shoulder, r_neck = rng.uniform(0.2, 0.35) * body, rng.uniform(0.010, 0.018)
    neck, cap = rng.uniform(0.01, 0.03), rng.uniform(0.01, 0.02)
    x = np.cumsum([0.0, body, shoulder, neck, cap])
    parts = (Part("cylinder", (r_body, body / 2), pos=((x[0] + x[1]) / 2, 0, 0), quat=_axis_to_x()),
             Part("mesh", vertices=_frustum(r_body, r_neck, shoulder, x[1], 0.0)),
             Part("cylinder", (r_neck, neck / 2), pos=((x[2] + x[3]) / 2, 0, 0), quat=_axis_to_x()),
             Part("cylinder", (r_neck + 0.002, cap / 2), pos=((x[3] + x[4]) / 2, 0, 0), quat=_axis_to_x()))
    if rng.random() < 0.4 and x[4] < 6 * r_body:  # a short, wide bottle stands
        parts = tuple(_turned(p, _axis_to_z_from_x()) for p in parts)
    return parts, "plastic-bottle"


def _mug(rng):
    radius, height, wall = rng.uniform(0.035, 0.05), rng.uniform(0.07, 0.12), rng.uniform(0.004, 0.006)
    parts = [*_ring(radius, radius, height, wall, 14), Part("cylinder", (radius, 0.003), pos=(0, 0, 0.003))]
    reach, grip = rng.uniform(0.02, 0.03), rng.uniform(0.5, 0.8) * height
    bar = 0.005
    x0 = radius + reach / 2
    z_low, z_high = (height - grip) / 2, (height + grip) / 2
    parts += [Part("box", (reach / 2, bar, bar), pos=(x0, 0, z)) for z in (z_low, z_high)]
    parts.append(Part("box", (bar, bar, grip / 2 + bar), pos=(radius + reach, 0, height / 2)))
    return tuple(parts), str(rng.choice(["hard-plastic", "glass"]))


def _bowl(rng):
    top = rng.uniform(0.06, 0.09)
    bottom, depth = rng.uniform(0.5, 0.7) * top, rng.uniform(0.04, 0.07)
    parts = [*_ring(bottom, top, depth, 0.005, 18), Part("cylinder", (bottom, 0.003), pos=(0, 0, 0.003))]
    return tuple(parts), "hard-plastic"


def _utensil(rng):
    handle, width, thick = rng.uniform(0.10, 0.16), rng.uniform(0.01, 0.02), rng.uniform(0.004, 0.008)
    head, head_width, head_thick = rng.uniform(0.04, 0.07), rng.uniform(0.03, 0.05), rng.uniform(0.006, 0.015)
    kind = "ellipsoid" if rng.random() < 0.5 else "box"
    return ((Part("box", (handle / 2, width / 2, thick / 2)),
             Part(kind, (head / 2, head_width / 2, head_thick / 2), pos=(handle / 2 + head / 2 - 0.005, 0, 0))),
            str(rng.choice(["steel", "hard-plastic"])))


def _tool(rng):
    radius, length = rng.uniform(0.01, 0.018), rng.uniform(0.12, 0.20)
    handle = Part("cylinder", (radius, length / 2), quat=_axis_to_x())
    if rng.random() < 0.5:  # a hammer's head across the handle's end
        size = rng.uniform([0.012, 0.04, 0.012], [0.02, 0.07, 0.02])
        head = Part("box", (size[0], size[1], max(size[2], radius)), pos=(length / 2 + size[0] - 0.004, 0, 0))
        return (handle, head), str(rng.choice(["wood", "steel"]))
    shaft_r, shaft = rng.uniform(0.002, 0.004), rng.uniform(0.06, 0.12)  # a screwdriver's shaft
    return (handle, Part("cylinder", (shaft_r, shaft / 2), pos=(length / 2 + shaft / 2, 0, shaft_r - radius),
                         quat=_axis_to_x())), "hard-plastic"


def _small(rng):
    kind = str(rng.choice(["sphere", "box", "ellipsoid"]))
    if kind == "sphere":
        return (Part("sphere", (rng.uniform(0.015, 0.035),)),), str(rng.choice(["rubber", "plastic-fruit"]))
    if kind == "box":
        return (Part("box", tuple(rng.uniform(0.01, 0.025, 3))),), "wood"
    return (Part("ellipsoid", tuple(rng.uniform([0.02, 0.015, 0.015], [0.035, 0.025, 0.025]))),), "plastic-fruit"


def _stone(rng):
    base = rng.uniform(0.035, 0.065)
    amplitudes, phases = rng.uniform(0, [0.18, 0.10, 0.06, 0.04]), rng.uniform(0, 2 * np.pi, 4)

    def radius(theta):
        return base * (1 + sum(a * np.cos((k + 2) * theta + p) for k, (a, p) in enumerate(zip(amplitudes, phases))))

    return _pebble(radius, top=rng.uniform(0.012, 0.03), bottom=rng.uniform(0.010, 0.02)), "stone"


_BUILDERS = {"box": _box, "cylinder": _cylinder, "bottle": _bottle, "mug": _mug, "bowl": _bowl,
             "utensil": _utensil, "tool": _tool, "small": _small, "stone": _stone}


def _ring(r_bottom: float, r_top: float, height: float, wall: float, n: int) -> list[Part]:
    """A thin wall of revolution from radius ``r_bottom`` at z = 0 to ``r_top`` at ``height``, as ``n`` convex
    segments (the hulls of their eight corners), overlapping a little so the ring is closed."""
    parts = []
    half = np.pi / n * 1.08
    for a in np.arange(n) * 2 * np.pi / n:
        corners = [(r + dr) * np.array([np.cos(a + s), np.sin(a + s), 0.0]) + [0, 0, z]
                   for r, z in ((r_bottom, 0.0), (r_top, height)) for dr in (0.0, wall) for s in (-half, half)]
        parts.append(Part("mesh", vertices=np.array(corners)))
    return parts


def _resting(parts) -> tuple[Part, ...]:
    """``parts`` moved so that their lowest point is at z = 0 and their extent is centred on x, y = 0."""
    points = np.vstack([p.surface_points() for p in parts])
    shift = -np.array([(points[:, 0].max() + points[:, 0].min()) / 2, (points[:, 1].max() + points[:, 1].min()) / 2,
                       points[:, 2].min()])
    return tuple(_moved(p, shift) for p in parts)


def _moved(part: Part, shift) -> Part:
    return Part(part.kind, part.size, tuple(np.asarray(part.pos) + shift), part.quat, part.vertices, part.faces)


def _turned(part: Part, quat) -> Part:
    """``part`` turned by the rotation ``quat`` (w, x, y, z) about the object frame's origin."""
    turn = _quat_matrix(quat)
    pos = tuple(turn @ np.asarray(part.pos))
    if part.kind == "mesh":
        return Part("mesh", pos=pos, vertices=np.asarray(part.vertices) @ turn.T, faces=part.faces)
    return Part(part.kind, part.size, pos, _quat_product(quat, part.quat))


def _axis_to_z_from_x() -> tuple[float, float, float, float]:
    """The rotation turning the x axis onto z (-90 degrees about y)."""
    return (float(np.cos(np.pi / 4)), 0.0, float(-np.sin(np.pi / 4)), 0.0)


def _quat_product(a, b) -> tuple[float, float, float, float]:
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2, w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2, w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2)


def _volume(part: Part) -> float:
    """The volume of ``part``'s convex hull, m^3 (every part is convex)."""
    return float(ConvexHull(part.surface_points()).volume)


def _shade(rgba, rng) -> tuple[float, float, float, float]:
    """The material's colour, its brightness and hue varied a little by the seed."""
    rgb = np.clip(np.asarray(rgba[:3]) * rng.uniform(0.75, 1.15) + rng.uniform(-0.08, 0.08, 3), 0.05, 0.95)
    return (*(float(c) for c in rgb), 1.0)
