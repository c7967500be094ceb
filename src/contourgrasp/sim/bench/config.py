"""What a bench runs: objects x trials x planners, the scene, the object sets, and the thesis's objects and labels."""

from __future__ import annotations

from dataclasses import dataclass, field

from ...errors import SimulationError
from ...tolerances import MAX_ATTEMPTS, MAX_BENCH_TILT, MAX_BENCH_TRIALS, MAX_SEED, MAX_TRIALS
from ...hand import Hand
from ...io.hand_file import load_hand
from ...validation import bounded, choice, integer
from ..clearing import ATTEMPTS_PER_OBJECT, run_clearing
from ..clutter import SCENE_KINDS
from ..tendon_hand import build_hand
from ..objects import THESIS_OBJECTS, ObjectSpec, object_spec
from ..planners import BASELINES, make_planner, synthesis_planner
from ..render import DEFAULT_SENSOR, SENSORS
from ..scene import Camera, Workspace
from ..trial import DROPPED, FAILURE_CAUSES, HIT, MISSED, NO_PLAN, PUSHED, SLIPPED, STRUCK, TrialRecord, run_trial
from ..procedural import procedural_names
from ..ycb import OBJECT_SETS, load_object, object_names

#: Success rates of Table 4.4 (real arm and qbHand, 10 trials per object).
THESIS_SUCCESS = {"can": 0.8, "case": 0.4, "bottle": 0.7, "stone1": 0.2, "stone2": 0.6}
#: Column headings of Table 4.4 for the simulated objects.
LABELS = {"can": "can", "case": "glasses case", "bottle": "bottle", "stone1": "stone 1", "stone2": "stone 2"}
#: What a bench's trial is: one grasp of a target (``trials``), or clearing its scene (``clear``,
#: :mod:`contourgrasp.sim.clearing`).
PROTOCOLS = ("trials", "clear")
#: Short failure causes for the trial tables.
SHORT_CAUSES = {NO_PLAN: "no plan", STRUCK: "struck", MISSED: "missed", PUSHED: "pushed", SLIPPED: "slipped",
                DROPPED: "dropped", HIT: "hit"}


@dataclass(frozen=True)
class Bench:
    """What to run: objects x trials x planners, and the scene.

    Attributes
    ----------
    objects : tuple of ObjectSpec
        Distinct names; they head the table's columns.
    planners : tuple of str
        Planner names (:func:`~contourgrasp.sim.planners.make_planner`).
    trials : int
        Per object and planner.
    seed : int
        Trial ``t`` uses seed ``seed + t``.
    hand : Hand
        Simulated, and planned for.
    sensor : str
        The depth sensor of the planner's picture: a preset of :data:`~contourgrasp.sim.render.SENSORS`
        (default :data:`~contourgrasp.sim.render.DEFAULT_SENSOR`, a structured-light camera; ``ideal``: exact).
    tilt : float or None
        The camera's tilt from looking straight down, rad, for every trial (at most ``MAX_BENCH_TILT``);
        None: top-down for ``single`` scenes, the seed's 0-25 deg for ``clutter`` and ``bin``.
    robot : bool
        A robot arm in every picture (:data:`~contourgrasp.sim.mjcf.ROBOT_ARM`), seen and never touched.
    camera, workspace
        Scene parameters (:mod:`contourgrasp.sim.scene`).
    splits : tuple of (str, tuple of str)
        Named object sets (``ycb-train``, ``ycb-test``, ...) and the names of
        their objects, for the per-split report; empty: no split, the thesis's
        report.
    hand_model : MountedHand, optional
        A MuJoCo hand model simulated as itself (:func:`~contourgrasp.handmodels.mount.mount_model`);
        ``hand`` is then its derived hand file. None: the simulated hand is built from ``hand``.
    scene_kind : {"single", "clutter", "bin"}
        The scene of every trial (:mod:`contourgrasp.sim.clutter`). In
        ``clutter`` and ``bin`` each object is in turn the target, its
        neighbours drawn from :meth:`pool`.
    attempts : int
        At most this many attempts per trial, a failure told from a new picture and the next plan
        avoiding the grasps that failed (:func:`~contourgrasp.sim.trial.run_trial`).
    protocol : {"trials", "clear"}
        ``trials``: each trial grasps its target (:func:`~contourgrasp.sim.trial.run_trial`); ``clear``
        (``clutter`` and ``bin`` scenes, one attempt per plan): each trial clears its scene, the planner
        choosing what to pick (:func:`~contourgrasp.sim.clearing.run_clearing`).

    Raises
    ------
    SimulationError
        No object, repeated object or planner names, an unknown planner, fewer
        than one trial, a negative seed, a split naming an object the bench does
        not run, or a hand the simulation cannot build.
    """

    objects: tuple[ObjectSpec, ...]
    planners: tuple[str, ...] = ("paper", "default", *BASELINES)
    trials: int = 20
    seed: int = 0
    hand: Hand = field(default_factory=lambda: load_hand("five-finger-linear"))
    sensor: str = DEFAULT_SENSOR
    tilt: float | None = None
    robot: bool = False
    camera: Camera = field(default_factory=Camera)
    workspace: Workspace = field(default_factory=Workspace)
    splits: tuple[tuple[str, tuple[str, ...]], ...] = ()
    hand_model: object = None
    scene_kind: str = "single"
    attempts: int = 1
    protocol: str = "trials"

    def __post_init__(self):
        choice("scene", self.scene_kind, SCENE_KINDS, error=SimulationError)
        choice("protocol", self.protocol, PROTOCOLS, error=SimulationError)
        if self.protocol == "clear" and self.scene_kind == "single":
            raise SimulationError("protocol 'clear' needs a scene of several objects: scene 'clutter' or 'bin'")
        if self.protocol == "clear" and self.attempts != 1:
            raise SimulationError(f"attempts must be 1 with protocol 'clear' (it makes its own: up to "
                                  f"{ATTEMPTS_PER_OBJECT} per object), got {self.attempts!r}")
        choice("sensor", self.sensor, tuple(SENSORS), error=SimulationError)
        if not isinstance(self.robot, bool):
            raise SimulationError(f"robot must be True or False, got {self.robot!r}")
        if self.tilt is not None:
            object.__setattr__(self, "tilt", bounded("tilt", self.tilt, MAX_BENCH_TILT, " rad", error=SimulationError))
        object.__setattr__(self, "objects", tuple(self.objects))
        object.__setattr__(self, "planners", tuple(self.planners))
        object.__setattr__(self, "splits", tuple((str(s), tuple(members)) for s, members in self.splits))
        names = [o.name for o in self.objects]
        if not names:
            raise SimulationError("no object to grasp")
        if len(set(names)) != len(names):
            raise SimulationError(f"object names must differ, got {', '.join(names)}")
        if not self.planners or len(set(self.planners)) != len(self.planners):
            raise SimulationError(f"planners must be distinct names, got {', '.join(self.planners) or 'none'}")
        for planner in self.planners:
            synthesis_planner(planner)  # refuses an unknown name before any trial runs
        object.__setattr__(self, "trials", integer("trials", self.trials, 1, maximum=MAX_TRIALS, error=SimulationError))
        object.__setattr__(self, "seed", integer("seed", self.seed, 0, maximum=MAX_SEED, error=SimulationError))
        object.__setattr__(self, "attempts", integer("attempts", self.attempts, 1, maximum=MAX_ATTEMPTS,
                                                     error=SimulationError))
        if self.size > MAX_BENCH_TRIALS:
            raise SimulationError(f"the bench asks for {self.size} trials ({len(names)} objects x {self.trials} trials x "
                                  f"{len(self.planners)} planners): at most {MAX_BENCH_TRIALS} in one bench")
        for split, members in self.splits:
            missing = [m for m in members if m not in names]
            if missing or not members:
                raise SimulationError(f"split {split!r} names {missing[0] if missing else 'no object'}, "
                                      f"which the bench does not run")
        if self.hand_model is None:
            build_hand(self.hand)  # refuses a hand the simulation cannot build before any trial runs

    @property
    def size(self) -> int:
        """Number of trials."""
        return len(self.objects) * self.trials * len(self.planners)

    def object(self, name: str) -> ObjectSpec:
        """The object called ``name``."""
        return next(o for o in self.objects if o.name == name)

    def split_of(self, name: str) -> str | None:
        """The first split the object called ``name`` belongs to (None: none)."""
        return next((split for split, members in self.splits if name in members), None)

    def pool(self, name: str) -> tuple[ObjectSpec, ...]:
        """The neighbours of the target called ``name``: the bench's other objects of its split (all, without
        splits), so that ``ycb-test`` targets stand among ``ycb-test`` objects; the object itself when it is alone."""
        split = self.split_of(name)
        members = dict(self.splits)[split] if split else [o.name for o in self.objects]
        return tuple(o for o in self.objects if o.name in members and o.name != name) or (self.object(name),)

    @property
    def causes(self) -> tuple[str, ...]:
        """The failure causes its trials can have: the hit of a neighbour only where there are neighbours."""
        return FAILURE_CAUSES if self.scene_kind != "single" else tuple(c for c in FAILURE_CAUSES if c != HIT)

    def tasks(self) -> list[tuple[str, int, int]]:
        """Every trial as (planner, object index, trial), object by object (so objects finish one after another)."""
        return [(planner, index, trial) for index in range(len(self.objects)) for planner in self.planners
                for trial in range(self.trials)]

    def run(self, planner: str, obj: ObjectSpec, trial: int, *, plan=None, observe=None) -> TrialRecord:
        """Run one trial; ``plan`` replaces the named planner's callable (same answers), ``observe`` see run_trial."""
        seed = self.seed + trial
        pool = self.pool(obj.name) if self.scene_kind != "single" else ()
        common = {"seed": seed, "planner": plan or make_planner(planner, self.hand, seed=seed),
                  "hand": self.hand if self.hand_model is None else self.hand_model, "sensor": self.sensor,
                  "tilt": self.tilt, "camera": self.camera, "workspace": self.workspace, "observe": observe,
                  "scene_kind": self.scene_kind, "pool": pool, "robot": self.robot}
        if self.protocol == "clear":
            return run_clearing(obj, **common)
        return run_trial(obj, **common, attempts=self.attempts)


@dataclass(frozen=True)
class BenchTrial:
    """One trial of the bench: which planner, which trial (0-based), and its record."""

    planner: str
    trial: int
    record: TrialRecord


def resolve_objects(objects) -> tuple[tuple[ObjectSpec, ...], tuple[tuple[str, tuple[str, ...]], ...]]:
    """The objects of ``--objects`` and the splits it names: ``(objects, splits)`` for :class:`Bench`.

    Every name is checked before any object is loaded. A set name of
    :data:`OBJECT_SETS` or a procedural set (``procedural:N``,
    ``procedural-test:N``: :mod:`~contourgrasp.sim.procedural`) among ``objects``
    becomes a split (its members' object names); plain object names belong to none.

    Raises
    ------
    SimulationError
        An unknown name.

    Examples
    --------
    >>> objects, splits = resolve_objects("thesis")
    >>> [o.name for o in objects] == list(splits[0][1])
    True
    """
    tokens = [t.strip() for t in objects.split(",")] if isinstance(objects, str) else [str(t) for t in objects]
    from tqdm import tqdm

    # The first run on a machine decomposes every non-convex mesh (CoACD, up to a minute and a half each):
    # a bar on a terminal says which object it is on; once cached, loading all 41 YCB objects takes seconds.
    loaded = object_names(tokens)
    specs = tuple(load_object(n) for n in tqdm(loaded, desc="loading objects", unit="object", leave=False,
                                                 disable=None))
    name_of = {n: o.name for n, o in zip(loaded, specs, strict=True)}
    splits = tuple((t, tuple(name_of[n] for n in object_names([t]))) for t in dict.fromkeys(tokens)
                   if t in OBJECT_SETS or procedural_names(t) is not None)
    return specs, splits


def thesis_objects(names) -> tuple[ObjectSpec, ...]:
    """The objects of :data:`~contourgrasp.sim.objects.THESIS_OBJECTS` called ``names``.

    Raises
    ------
    SimulationError
        An unknown name.
    """
    _known(names)
    return tuple(object_spec(n) for n in names)


def _known(names) -> None:
    unknown = [n for n in names if n not in THESIS_OBJECTS]
    if unknown:
        raise SimulationError(f"unknown object {unknown[0]!r}: choose from {', '.join(THESIS_OBJECTS)} "
                              f"or pass --mesh FILE")


def label(name: str) -> str:
    """Column heading of an object."""
    return LABELS.get(name, name)
