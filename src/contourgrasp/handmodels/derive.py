"""A hand file from a MuJoCo model of a hand: close it in free air and fit the thesis's trajectories (3.3).

Reading of the model
--------------------
*Palm.* The palm body (default: the deepest body holding every fingertip) is fixed: every joint
outside its subtree is held at its reference position (a free joint, an arm's joints), gravity is
off (a hand on an arm is gravity-compensated; the bench's hand is) and so are contacts (free air:
the fingers pass each other, as the bench's hand geoms do).

*Synergy.* The named actuators (default: all whose joints lie on the palm's subtree) are driven
together, the one-DoF power grasp of the thesis: at synergy ``u`` in [0, 1] every control is
``open + u * (closed - open)``, the two ends of its ``ctrlrange`` (a position servo's joint angles,
a motor's or tendon's force). The hand settles open for :data:`SETTLE_TIME`, ``u`` ramps from 0 to
1 over ``close_time`` and holds for ``hold_time``. *Open* is the low end of every range unless the
fingertips end farther apart (mean distance from their centroid) than they began: then the run is
repeated from the high ends to the low ones. A finger is *closed* where its projected tip is
farthest from where it was open: a curling finger's tip swings back under the palm at the end,
which no ray or arc follows and an object in the way never sees. Actuators outside the synergy
keep control 0, except those a :class:`ModelSpec` holds (a pre-shape); its ``open_from`` starts the
synergy part of the way to closed (a pre-flexed open hand), and the simulation opens the hand as far.

*Frames.* The 3-D hand frame is the palm body's frame with its axes renamed: z (the approach, toward
the object) is the :class:`ModelSpec`'s ``approach`` axis, or else the palm axis (+-x, +-y or +-z)
best aligned with the mean direction from each finger's first hinge joint (the palm's origin for a
finger without one) to its open fingertip -- the way the fingers point; x is the first of the palm's
axes not along z, y = z x x. The reading ``approach = "level"`` (:data:`LEVEL`) turns that frame
about the axis normal to z and to the offset of the first fingertip's open tip from the deepest of
the others' (along z before the turn), until the two are equally deep: the hand approaches tilted
so that an opposed thumb shorter than the fingers reaches the object with them, as low as the
lowest finger (the grasp height counts from the lowest open tip). Our reading for a humanlike
hand: along the fingers, the Inspire's open fingertips hang 134-147 mm below the palm and its
thumb's 48 mm, so a descent that brings the fingers to the object leaves the thumb a hand's width
above it; levelled, they meet it together (docs/hand-models.md, "The bench on the models", for what it lifts).
It needs two fingers at least, the first not straight along the approach from the others. The origin
is the palm body's origin moved along z to the palm's underside: the largest z of the palm's own
collision geoms (those of bodies welded to it), but no deeper than the shallowest finger's first
joint (posts below the palm carry knuckles), so z = 0 is the plane of the palm's underside as in
:mod:`contourgrasp.hand`; the palm plane is the plane z = 0, and the fingertips' paths are projected
on it along z.

*Trajectories.* Each fingertip's path, projected on the palm plane, is fitted by a ray (eq 3.18:
start the open tip, direction and travel to the closed tip) and, when the ray leaves the path by more
than ``tolerances.MODEL_FIT_TOLERANCE``, by an axis-aligned elliptic arc (eq 3.20, fitted as a conic
by least squares); the fit error is the largest distance of the path from the fitted trajectory. A
finger no trajectory fits within the tolerance is refused, naming it.

*Virtual starts* come from the recorded closing, as :mod:`contourgrasp.sim.calibrate` derives them
for the simulated hand (reference: the finger that closes last).

*3-D chain.* A ray finger whose path from the palm to its tip has exactly two moving hinge joints is
given a :class:`~contourgrasp.hand.FingerChain`: knuckle at the first joint, links from joint to
joint to tip, its open and closed joint angles measured in the chain's plane, when it passes
:func:`~contourgrasp.hand.check_chain`. Any other finger (an arc, more hinges, a chain out of its
plane) is given its chain as measured, a :class:`~contourgrasp.hand.SampledChain`: its hinges'
anchors and its tip along the recorded closing (:func:`~contourgrasp.handmodels.fit.sampled_chain`),
every link a capsule of the finger's radius (a bounding capsule of each link's geoms was tried and
refused too much: docs/hand-models.md, "The bench on the models"). The palm
(:func:`~contourgrasp.handmodels.fit.palm_plate`): one collision geom's box gives its tilted
underside face; several give their rectangle, as deep as their deepest corner. The hand keeps
its chains and palm only when every finger has a chain; otherwise it is a 2-D hand, and
:attr:`Derivation.notes` says why. Finger radius: half the smallest extent of the
fingertip body's collision geoms.

*Parts.* The palm, the fingertips, the actuators, the hinge chains and the geoms' boxes are found by
name in :mod:`contourgrasp.handmodels.lookup`, which refuses a name the model does not have.

*Forces* (:func:`contourgrasp.handmodels.force.fingertip_forces`, not part of the hand file): how hard
each fingertip pushes along its path during the same closing, read from the drives' joint forces.

*Gains.* The model says nothing about the planner's gains: every finger gets ``alpha`` 25 and
``beta`` 10000 (the five-finger preset's), none is required, and ``min_touching`` is every finger
for up to three fingers, all but one beyond.
"""

from __future__ import annotations

import os
from contextlib import contextmanager
from dataclasses import dataclass, replace
from importlib import resources
from pathlib import Path

import numpy as np

os.environ.setdefault("MUJOCO_GL", "disable")
import mujoco  # noqa: E402

from .. import tolerances as tol  # noqa: E402
from .. import validation  # noqa: E402
from ..errors import HandError, HandFileError, SimulationError  # noqa: E402
from ..hand import SLICE_CONTOUR, Hand, Palm, SampledChain  # noqa: E402
from . import lookup  # noqa: E402
from ..sim.calibrate import FingerTravel, derive_virtual_starts  # noqa: E402
from .fit import FingerFit, fit_chain, fit_finger, palm_plate, sampled_chain, travelled  # noqa: E402
from ..sim.mjcf import TIMESTEP  # noqa: E402
from ..sim.scene import mujoco_warnings  # noqa: E402

#: Time the open hand settles before closing, s.
SETTLE_TIME = 2.0
#: Miss penalty of a derived hand (the five-finger-linear preset's).
MISS_PENALTY = 250.0
#: The approach reading that levels the first fingertip (the thumb) with the others (module docstring).
LEVEL = "level"
#: The approach reading along the fingers (a ModelSpec's None), to override a bundled model's.
ALONG_FINGERS = "fingers"


@dataclass(frozen=True)
class ModelSpec:
    """Where a hand model is and how to read it: the MJCF file, its fingertips, synergy actuators, palm.

    Attributes
    ----------
    path : str
    fingertips : tuple of str
        Site or body names, one per finger (a body stands for its origin).
    actuators : tuple of str or None
        The synergy's actuators; None: all on the palm's subtree.
    palm : str or None
        The palm body; None: the deepest body holding every fingertip.
    names : tuple of str or None
        Finger names in the hand file; None: the fingertips' names.
    hold : tuple of (str, float)
        Actuators outside the synergy held at a fraction of their control range throughout (a
        pre-shape, such as a thumb's opposition); any other actuator keeps control 0.
    approach : str or None
        The palm axis (``"x"``, ``"-x"``, ..., ``"-z"``) that is the approach (the hand frame's z);
        None: the axis the fingers point along; :data:`LEVEL`: that axis turned until the first
        fingertip is as deep as the others (module docstring).
    max_imbalance : float
        The derived hand's :attr:`Hand.max_imbalance`: closing the model in free air does not show
        how unbalanced a squeeze its drive holds, so it is chosen on the bench, not derived.
    tips_brush_table : bool
        The derived hand's :attr:`Hand.tips_brush_table`, chosen on the bench for the same reason.
    grasp_height_fraction : float
        The derived hand's :attr:`Hand.grasp_height_fraction`, chosen on the bench for the same reason.
    slice_contour : bool or "unbalanced"
        The derived hand's :attr:`Hand.slice_contour`, chosen on the bench for the same reason.
    open_from : float
        The synergy's open end as a fraction of the way from its open to its closed controls, in [0, 1):
        the hand opens only that far, a pre-flexed open hand (0: fully open). For a hand whose fingers,
        fully open, point along the approach, so that curling they first swing out and up; the
        simulation opens the hand as far (:attr:`Mount.open_controls`).

    Raises
    ------
    HandError
        A ``max_imbalance``, ``grasp_height_fraction`` or ``open_from`` out of range, a ``slice_contour`` not
        one of :data:`~contourgrasp.hand.SLICE_CONTOUR`.
    """

    path: str
    fingertips: tuple[str, ...]
    actuators: tuple[str, ...] | None = None
    palm: str | None = None
    names: tuple[str, ...] | None = None
    hold: tuple[tuple[str, float], ...] = ()
    approach: str | None = None
    max_imbalance: float = tol.HAND_MAX_IMBALANCE
    tips_brush_table: bool = False
    grasp_height_fraction: float = tol.GRASP_HEIGHT_FRACTION
    slice_contour: bool | str = "unbalanced"
    open_from: float = 0.0

    def __post_init__(self):
        # Checked as the Hand will check them, but before the model is closed for seconds.
        object.__setattr__(self, "max_imbalance",
                           validation.bounded("max_imbalance", self.max_imbalance, 1.0, error=HandError))
        object.__setattr__(self, "grasp_height_fraction", validation.bounded(
            "grasp_height_fraction", self.grasp_height_fraction, tol.MAX_GRASP_HEIGHT_FRACTION, error=HandError))
        object.__setattr__(self, "slice_contour",
                           validation.choice("slice_contour", self.slice_contour, SLICE_CONTOUR, error=HandError))
        object.__setattr__(self, "open_from", validation.bounded("open_from", self.open_from, 1.0, error=HandError))
        if self.open_from == 1.0:
            raise HandError("open_from must be below 1 (1 opens the hand not at all)")


def _bundled(folder: str, xml: str, fingers, **options) -> ModelSpec:
    path = resources.files("contourgrasp").joinpath(f"data/models/{folder}/{xml}")
    return ModelSpec(path=str(path), fingertips=tuple(f"{f}_tip" for f in fingers), **options)


#: The five-finger models' fingertip sites (``<finger>_tip``) and drives are named after these.
_FIVE_FINGERS = ("thumb", "index", "middle", "ring", "pinky")
#: The five-finger models' fingers by the names of our hand's.
_FIVE_FINGER_NAMES = ("thumb", "index", "middle", "ring", "little")

#: The hand models shipped with the package (the Inspire and the Jaco from robosuite 1.5.2, MIT; the MPL from the
#: dexterity 0.0.15 wheel, Apache-2.0; data/models/README.md). The
#: Inspire hand's thumb rotation is its own motor: held opposed (the high end), not part of the synergy; it is read
#: :data:`LEVEL` (chosen on ycb-train and the thesis's five: docs/hand-models.md, "The bench on the models"). The Jaco's
#: fingers each hold their own position: its squeeze's balance is off (max_imbalance 1), chosen on its ycb-train
#: and thesis's-five trials (docs/studies.md). The Inspire's fingertips brush the table
#: (tips_brush_table), the Jaco's do not: chosen on the same trials (docs/hand3d.md, "The 3-D hand in the plan"). The
#: Inspire's curling fingers are asked for no part of the object's height (grasp_height_fraction 0) and are planned on
#: the outline seen (slice_contour false): both chosen on its ycb-train trials (docs/hand-models.md, "The bench on the
#: models"). The MPL's thumb abduction is held at the top of its range (opposed), its synergy starts a fifth of the
#: way to closed (open_from 0.2: fully open, its fingers point down the approach and their curling tips rise past
#: the palm's underside) and its squeeze's balance is off: all three chosen on its thesis's-five and ycb-train
#: trials (docs/studies.md, "The MPL model").
MODELS = {
    "inspire": _bundled(
        "inspire", "inspire_right_hand.xml", _FIVE_FINGERS, palm="r_palm",
        names=_FIVE_FINGER_NAMES,
        actuators=tuple(f"{f}_{j}_drive" for f in _FIVE_FINGERS[1:] for j in ("proximal", "distal"))
        + ("thumb_proximal_2_drive", "thumb_middle_drive", "thumb_distal_drive"),
        hold=(("thumb_proximal_1_drive", 1.0),), approach=LEVEL, tips_brush_table=True, grasp_height_fraction=0.0,
        slice_contour=False),
    "jaco-three-finger": _bundled("jaco_three_finger", "jaco_three_finger_gripper.xml", ("thumb", "index", "pinky"),
                                  palm="right_gripper", names=("thumb", "index", "pinky"), max_imbalance=1.0),
    "mpl": _bundled("mpl", "mpl_right.xml", _FIVE_FINGERS, palm="palm", names=_FIVE_FINGER_NAMES,
                    actuators=tuple(f"A_{f}_MCP" for f in _FIVE_FINGERS) + ("A_thumb_PIP", "A_thumb_DIP"),
                    hold=(("A_thumb_ABD", 1.0),), approach=LEVEL, open_from=0.2, max_imbalance=1.0),
}


def model_spec(model, *, fingertips=None, actuators=None, palm=None, approach=None,
               max_imbalance=None, tips_brush_table=None, grasp_height_fraction=None, slice_contour=None) -> ModelSpec:
    """A :class:`ModelSpec` from a bundled model's name (:data:`MODELS`) or an MJCF path; options override.

    Raises
    ------
    HandFileError
        A path without fingertips.
    HandError
        ``fingertips`` or ``actuators`` not a list of names, ``palm`` not a name; a ``max_imbalance``,
        ``grasp_height_fraction`` or ``slice_contour`` the hand would refuse.
    """
    fingertips, actuators = _names("fingertips", fingertips), _names("actuators", actuators)
    if palm is not None and not isinstance(palm, str):
        raise HandError(f"palm must be a body's name, got {validation.shown(palm)}")
    if isinstance(model, ModelSpec):
        spec = model
    elif str(model) in MODELS:
        spec = MODELS[str(model)]
    else:
        if not fingertips:
            raise HandFileError(f"{model}: name the fingertips (sites or bodies) of the model")
        spec = ModelSpec(path=str(model), fingertips=tuple(fingertips))
        fingertips = None
    if fingertips:
        spec = replace(spec, fingertips=tuple(fingertips), names=None)
    if actuators is not None:
        spec = replace(spec, actuators=tuple(actuators))
    if approach is not None:
        spec = replace(spec, approach=None if approach == ALONG_FINGERS else approach)
    chosen = {"max_imbalance": max_imbalance, "tips_brush_table": tips_brush_table,
              "grasp_height_fraction": grasp_height_fraction, "slice_contour": slice_contour, "palm": palm}
    return replace(spec, **{k: v for k, v in chosen.items() if v is not None})


def _names(what: str, value) -> tuple[str, ...] | None:
    """``value`` as a tuple of names (None stays None): a list or tuple of strings, not one string."""
    if value is None:
        return None
    if isinstance(value, str) or not isinstance(value, (list, tuple)) or not all(isinstance(v, str) for v in value):
        raise HandError(f"{what} must be a list of names, got {validation.shown(value)}")
    return tuple(value)


@dataclass(frozen=True)
class Derivation:
    """A hand derived from a model: the hand, each finger's fit, and what was left out.

    Attributes
    ----------
    hand : Hand
    fits : tuple of FingerFit
    notes : tuple of str
        Why the hand has no 3-D chains, when it has none.
    mount : Mount
        How the simulation mounts and closes the model (:mod:`contourgrasp.handmodels.mount`).
    """

    hand: Hand
    fits: tuple[FingerFit, ...]
    notes: tuple[str, ...]
    mount: Mount


@dataclass(frozen=True)
class Mount:
    """Where the model's palm sits in the 3-D hand frame and how its synergy was driven.

    Attributes
    ----------
    palm : str
        The palm body.
    rotation : (3, 3) float
        The palm body's axes in the hand frame (columns): ``v_hand = rotation @ v_palm + position``.
    position : (3,) float
        The palm body's origin in the hand frame, m.
    actuators : tuple of str
        The synergy's actuators.
    open_controls, closed_controls : tuple of float
        Their controls with the hand open and closed.
    held : tuple of (str, float)
        Actuators outside the synergy and the controls they hold.
    finger_bodies : tuple of (str, int)
        Each body of a finger (the palm's children toward a fingertip and all below them) and the
        finger's index.
    tip_depth : float
        The fingertips' largest depth below the palm's underside while closing, m.
    palm_depth : float
        The depth below z = 0 of the palm's deepest collision geom (0 where the palm lies above
        z = 0), m. z = 0 is no deeper than the shallowest knuckle, so a palm reaching along the
        fingers (the Inspire's, read ``level``) lies partly below it.
    """

    palm: str
    rotation: tuple[tuple[float, float, float], ...]
    position: tuple[float, float, float]
    actuators: tuple[str, ...]
    open_controls: tuple[float, ...]
    closed_controls: tuple[float, ...]
    held: tuple[tuple[str, float], ...]
    finger_bodies: tuple[tuple[str, int], ...]
    tip_depth: float
    palm_depth: float = 0.0


@dataclass(frozen=True, eq=False)
class ClosingRecord:
    """A model closed in free air: per finger the tips in the hand frame over time, and its moving joints.

    Attributes
    ----------
    names : tuple of str
    times : (k,) float
        Seconds since the synergy began to ramp (0: the settled open hand).
    tips : (n, k, 3) float
        Fingertips in the 3-D hand frame (z toward the object), m.
    joints : tuple of (j, k, 3) float
        Per finger, the anchors of its moving hinge joints (palm to tip) over time, hand frame.
    radius : (n,) float
    palm : Palm or None
        The palm geoms' rectangle on the palm plane and their thickness; None without palm geoms.
    mount : Mount
    """

    names: tuple[str, ...]
    times: np.ndarray
    tips: np.ndarray
    joints: tuple[np.ndarray, ...]
    radius: np.ndarray
    palm: Palm | None
    mount: Mount


def derive_hand(model, *, fingertips=None, actuators=None, palm=None, approach=None, max_imbalance=None,
                tips_brush_table=None, grasp_height_fraction=None, slice_contour=None, name: str | None = None,
                close_time: float = 1.0, hold_time: float = 0.5) -> Derivation:
    """Close a MuJoCo hand model with one synergy and fit its hand file (module docstring).

    Parameters
    ----------
    model : str, Path or ModelSpec
        A bundled model's name (:data:`MODELS`) or an MJCF file.
    fingertips, actuators, palm, approach, max_imbalance, tips_brush_table, grasp_height_fraction, slice_contour
        Override the :class:`ModelSpec`'s (fingertips are required for a file).
    name : str, optional
        The hand's name; default the model file's stem.
    close_time, hold_time : float
        Synergy ramp (> 0) and hold (>= 0), s, each at most ``tolerances.MAX_MODEL_CLOSING_TIME``.

    Returns
    -------
    Derivation

    Raises
    ------
    HandFileError
        The model cannot be loaded, a fingertip, actuator or palm it does not have, or an actuator
        without a control range.
    HandError
        A fingertip the actuators do not move, or a path no ray or arc fits (naming the finger); a
        ``close_time`` or ``hold_time`` out of range.
    SimulationError
        The model is unstable while closing.
    """
    spec = model_spec(model, fingertips=fingertips, actuators=actuators, palm=palm, approach=approach,
                      max_imbalance=max_imbalance, tips_brush_table=tips_brush_table,
                      grasp_height_fraction=grasp_height_fraction, slice_contour=slice_contour)
    closed = record_closing(spec, close_time=close_time, hold_time=hold_time)
    fingers, fits, ends = [], [], []
    for i, finger_name in enumerate(closed.names):
        path = closed.tips[i, :, :2]
        ends.append(int(np.argmax(np.linalg.norm(path - path[0], axis=1))))
        finger, fit = fit_finger(finger_name, path[:ends[-1] + 1], radius=float(closed.radius[i]))
        fingers.append(finger)
        fits.append(fit)
    default_name = str(model) if isinstance(model, str) and model in MODELS else Path(spec.path).stem
    hand = Hand(name=name or default_name, fingers=tuple(fingers), min_touching=_min_touching(len(fingers)),
                miss_penalty=MISS_PENALTY, max_imbalance=spec.max_imbalance, tips_brush_table=spec.tips_brush_table,
                grasp_height_fraction=spec.grasp_height_fraction, slice_contour=spec.slice_contour,
                description=f"derived from {Path(spec.path).name} by hand-from-model")
    hand = _with_virtual_starts(hand, closed)
    hand, notes = _with_chains(hand, closed, ends)
    return Derivation(hand=hand, fits=tuple(fits), notes=notes, mount=closed.mount)


def _min_touching(n: int) -> int:
    return n if n <= 3 else n - 1


def record_closing(spec: ModelSpec, *, close_time: float = 1.0, hold_time: float = 0.5) -> ClosingRecord:
    """Load, fix the palm, close the synergy in free air and record the fingertips (module docstring)."""
    source = spec.path
    m = lookup.load_model(source)
    collides = (m.geom_contype != 0) | (m.geom_conaffinity != 0)
    run, acts, held, lo, hi, (tips_palm, joint_records, d) = simulate_closing(m, spec, close_time, hold_time)
    palm, tips, chains = run.palm, run.tips, run.chains
    subtree = lookup.subtree(m, palm)
    moved = np.linalg.norm(tips_palm - tips_palm[:, :1], axis=2).max(axis=1)
    if (still := np.flatnonzero(moved < tol.FINGER_MOVED)).size:
        i = int(still[0])
        raise HandError(f"{source}: fingertip {spec.fingertips[i]!r} does not move when the actuators "
                        f"({', '.join(m.actuator(a).name for a in acts)}) close (it moves "
                        f"{1000 * moved[i]:.2f} mm, at least {1000 * tol.FINGER_MOVED:g} mm)")
    roots = np.array([joint_records[i][0, 0] if len(c) else np.zeros(3) for i, c in enumerate(chains)])
    if spec.approach in (None, LEVEL):
        axes = _hand_axes(tips_palm[:, 0] - roots)
        axes = _levelled(axes, tips_palm[:, 0], source) if spec.approach == LEVEL else axes
    else:
        axes = _hand_axes(_axis(spec.approach, source)[None])
    palm_geoms = lookup.palm_geoms(m, d, palm, subtree, axes, collides)
    knuckles = [float(joint_records[i][0, 0] @ axes[2]) for i, c in enumerate(chains) if len(c)]
    depth = 0.0 if palm_geoms is None else min([float(palm_geoms[:, 2].max())] + knuckles)
    shift = np.array([0.0, 0.0, depth])
    tips_hand = tips_palm @ axes.T - shift
    mount = Mount(palm=m.body(palm).name, rotation=tuple(map(tuple, axes.tolist())), position=tuple(-shift),
                  actuators=tuple(m.actuator(a).name for a in acts), open_controls=tuple(lo.tolist()),
                  closed_controls=tuple(hi.tolist()), held=tuple((m.actuator(a).name, v) for a, v in held),
                  finger_bodies=lookup.finger_bodies(m, palm, tips), tip_depth=float(tips_hand[:, :, 2].max()),
                  palm_depth=0.0 if palm_geoms is None else max(0.0, float(palm_geoms[:, 2].max()) - depth))
    return ClosingRecord(names=tuple(spec.names or spec.fingertips), times=m.opt.timestep * np.arange(tips_palm.shape[1]),
                       tips=tips_hand, mount=mount,
                       joints=tuple(np.transpose(j, (1, 0, 2)) @ axes.T - shift for j in joint_records),
                       radius=np.array([lookup.tip_radius(m, t, collides) for t in tips]),
                       palm=None if palm_geoms is None else palm_plate(palm_geoms - shift))


def simulate_closing(m, spec: ModelSpec, close_time: float, hold_time: float):
    """Set ``m`` up for a closing in free air (module docstring) and close it once: (run, actuators, held,
    open_controls, closed_controls, closing).

    ``run`` (:class:`ClosingSimulation`) closes the hand again from fresh data when called; ``actuators`` are the
    synergy's, ``held`` the (actuator, control) pairs kept at their pre-shape; the controls are the
    synergy's ends (the low ends of the ranges open the hand unless the fingertips end farther apart
    than they began); ``closing`` is ``run``'s record of the closing from open to closed.
    """
    run, acts, held = _set_up_free_air(m, spec, close_time, hold_time)
    lo, hi = run.m.actuator_ctrlrange[acts, 0], run.m.actuator_ctrlrange[acts, 1]
    closing = run(acts, lo, hi, held, spec.path)
    if _spread(closing[0][:, -1]) > _spread(closing[0][:, 0]):  # the high ends open the hand: close toward the low
        lo, hi = hi, lo
        closing = run(acts, lo, hi, held, spec.path)
    if spec.open_from > 0:  # a pre-shape: the synergy opens only part of the way
        lo = lo + spec.open_from * (hi - lo)
        closing = run(acts, lo, hi, held, spec.path)
    return run, acts, held, lo, hi, closing


def _set_up_free_air(m, spec: ModelSpec, close_time: float, hold_time: float) -> tuple[ClosingSimulation, np.ndarray, list]:
    """Set ``m`` up for a closing in free air and the run that closes it, with the synergy's actuators and
    the held ones."""
    source = spec.path
    close_time = validation.bounded("close_time", close_time, tol.MAX_MODEL_CLOSING_TIME, " s", strict=True,
                                    error=HandError)
    hold_time = validation.bounded("hold_time", hold_time, tol.MAX_MODEL_CLOSING_TIME, " s", error=HandError)
    m.opt.gravity[:] = 0.0
    m.opt.timestep, m.opt.integrator = TIMESTEP, mujoco.mjtIntegrator.mjINT_IMPLICITFAST  # the scene's
    m.geom_contype[:] = m.geom_conaffinity[:] = 0  # free air: nothing to touch, fingers pass each other (as in the scene)
    palm = lookup.palm_body(m, spec.palm, spec.fingertips, source)
    subtree = lookup.subtree(m, palm)
    tips = [lookup.fingertip(m, name, subtree, source) for name in spec.fingertips]
    acts = lookup.actuators(m, spec.actuators, subtree, source)
    held = lookup.held_controls(m, spec.hold, subtree, source)
    steps = tuple(max(1, round(t / m.opt.timestep)) for t in (SETTLE_TIME, close_time, hold_time))
    run = ClosingSimulation(m, palm, tips, [lookup.moving_path(m, tip, palm) for tip in tips],
                     frozen=[j for j in range(m.njnt) if m.jnt_bodyid[j] not in subtree], steps=steps)
    return run, acts, held


def _spread(points: np.ndarray) -> float:
    """Mean distance of the fingertips (n, 3) from their centroid."""
    return float(np.linalg.norm(points - points.mean(axis=0), axis=1).mean())


@dataclass(frozen=True, eq=False)
class ClosingSimulation:
    """One closing of the model from fresh data: settle open, ramp the synergy, hold."""

    m: mujoco.MjModel
    palm: int
    tips: list
    chains: list
    frozen: list
    steps: tuple[int, int, int]

    def __call__(self, acts, open_ctrl, closed_ctrl, held, source, probe=None):
        """Fingertips (n, k, 3) and per finger its hinge anchors (k, j, 3), palm frame, and the final data.

        ``probe(k, data)``, if given, is called after every step k (its state unchanged on return)."""
        m, d = self.m, mujoco.MjData(self.m)
        settle, ramp, hold = self.steps
        for a, value in held:
            d.ctrl[a] = value
        records, joint_records = [], []
        with mujoco_warnings(), _fatal_as(source):
            for k in range(settle + ramp + hold + 1):
                u = min(1.0, max(0.0, (k - settle) / ramp))
                d.ctrl[acts] = open_ctrl + u * (closed_ctrl - open_ctrl)
                lookup.freeze(m, d, self.frozen)
                mujoco.mj_step(m, d) if k else mujoco.mj_forward(m, d)
                if probe is not None:
                    probe(k, d)
                if k >= settle:
                    position, rotation = d.xpos[self.palm].copy(), d.xmat[self.palm].reshape(3, 3).copy()
                    records.append([(lookup.tip_point(d, t) - position) @ rotation for t in self.tips])
                    joint_records.append([(d.xanchor[c] - position) @ rotation for c in self.chains])
        if d.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0 or not np.isfinite(np.asarray(records)).all():
            raise SimulationError(f"{source}: the model is unstable while closing (NaN or huge accelerations)")
        joints = [np.asarray([r[i] for r in joint_records]).reshape(len(records), len(c), 3)
                  for i, c in enumerate(self.chains)]
        return np.transpose(np.asarray(records), (1, 0, 2)), joints, d


@contextmanager
def _fatal_as(source: str):
    """MuJoCo's own fatal errors (out of its memory arena, ...) as the SimulationError of the model ``source``."""
    try:
        yield
    except mujoco.FatalError as err:
        raise SimulationError(f"{source}: MuJoCo cannot simulate the model ({' '.join(str(err).split())[:200]})") from None


def _axis(name: str, source: str) -> np.ndarray:
    """The palm axis called ``name`` ("x", "-y", ...) as a unit 3-vector."""
    axes = {f"{sign}{a}": (-1.0 if sign else 1.0) * np.eye(3)[i] for i, a in enumerate("xyz") for sign in ("", "-")}
    if name not in axes:
        raise HandFileError(f"{source}: approach must be one of {', '.join([*axes, LEVEL, ALONG_FINGERS])}, "
                            f"got {name!r}")
    return axes[name]


def _levelled(axes: np.ndarray, open_tips: np.ndarray, source: str) -> np.ndarray:
    """``axes`` turned about the axis normal to z and to the first open tip's offset from the deepest of the
    others (along ``axes``' z), until the two tips are equally deep (the reading :data:`LEVEL`)."""
    if len(open_tips) < 2:
        raise HandFileError(f"{source}: approach {LEVEL!r} levels the first fingertip with the others: it needs two "
                            f"fingertips at least, got {len(open_tips)}")
    offset = open_tips[0] - open_tips[1 + int(np.argmax(open_tips[1:] @ axes[2]))]
    z = axes[2] - (axes[2] @ offset) * offset / max(float(offset @ offset), 1e-18)
    if np.linalg.norm(z) < 1e-3:
        raise HandFileError(f"{source}: approach {LEVEL!r}: the first fingertip lies straight along the fingers "
                            "from the others, so no tilt levels it; name a palm axis instead")
    z /= np.linalg.norm(z)
    x = axes[0] - (axes[0] @ z) * z
    x /= np.linalg.norm(x)
    return np.stack([x, np.cross(z, x), z])


def _hand_axes(pointing: np.ndarray) -> np.ndarray:
    """(3, 3) rows x, y, z of the hand frame in palm coordinates: z the signed palm axis nearest ``pointing``."""
    mean = pointing.mean(axis=0)
    k = int(np.argmax(np.abs(mean)))
    z = np.zeros(3)
    z[k] = np.sign(mean[k]) or 1.0
    x = np.eye(3)[0 if k else 1]
    return np.stack([x, np.cross(z, x), z])


def finger_travel(hand: Hand, closed: ClosingRecord) -> FingerTravel:
    """The free-air closing of ``closed`` as distances along ``hand``'s fitted trajectories (its virtual starts' source)."""
    progress = np.array([travelled(f, closed.tips[i, :, :2]) for i, f in enumerate(hand.fingers)])
    # an arc runs from the path's first point, which may lie off the fitted ellipse by the fit error: its
    # nearest point to the closed tip can fall that much short of the travel, which is the finger closed
    reached = np.minimum([f.travel for f in hand.fingers], progress.max(axis=1))
    return FingerTravel(names=closed.names, travel=reached, times=closed.times, travelled=progress)


def _with_virtual_starts(hand: Hand, closed: ClosingRecord) -> Hand:
    starts = derive_virtual_starts(finger_travel(hand, closed))
    fingers = tuple(replace(f, virtual_start=round(starts[f.name], 4) + 0.0) for f in hand.fingers)
    return replace(hand, fingers=fingers)


def _with_chains(hand: Hand, closed: ClosingRecord, ends: list[int]) -> tuple[Hand, tuple[str, ...]]:
    if closed.palm is None:
        return hand, ("the palm body has no collision geoms: no [palm], so no 3-D chains",)
    chains, notes = [], []
    for i, finger in enumerate(hand.fingers):
        k = ends[i] + 1
        chain, why = fit_chain(finger, closed.tips[i, :k], closed.joints[i][:, :k])
        if chain is None:
            chain, why_not = sampled_chain(finger, closed.tips[i, :k], closed.joints[i][:, :k])
            if chain is None:
                notes.append(f"{why}; measured: {why_not}")
        chains.append(chain)
    if notes:
        return hand, tuple(notes)
    return replace(hand, chains=tuple(chains), palm=closed.palm), ()


def fit_table(derivation: Derivation) -> list[str]:
    """Lines of a plain-text table: per finger its trajectory, start, travel, virtual start and fit error."""
    lines = [f"{'finger':8s} {'fit':4s} {'start x, y mm':>16s} {'travel mm':>10s} {'lambda_virt mm':>15s} "
             f"{'fit error mm':>13s} {'ray error mm':>13s}"]
    for f, fit in zip(derivation.hand.fingers, derivation.fits, strict=True):
        start = f"{1000 * f.start[0]:.1f}, {1000 * f.start[1]:.1f}"
        lines.append(f"{f.name:8s} {fit.kind:4s} {start:>16s} {1000 * f.travel:10.1f} {1000 * f.virtual_start:+15.1f} "
                     f"{1000 * fit.error:13.2f} {1000 * fit.ray_error:13.2f}")
    hand = derivation.hand
    if hand.is_3d:
        measured = [f.name for f, c in zip(hand.fingers, hand.chains, strict=True) if isinstance(c, SampledChain)]
        tilted = ", the palm tilted" if hand.palm.depths is not None else ""
        lines.append("3-D chains and palm: yes" + (f" (as measured: {', '.join(measured)}{tilted})" if measured
                                                   else f" ({tilted[2:]})" if tilted else ""))
    else:
        lines.append("3-D chains and palm: no (" + "; ".join(derivation.notes) + ")")
    return lines
