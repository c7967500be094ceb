"""Numerical tolerances and sampling resolutions, in one place.

Every threshold the package compares against lives here, so that a reader
can see at a glance what "zero", "the same point" or "too big" mean.
All lengths are in meters.
"""

#: Two contour points closer than this are the same point (duplicates are dropped).
POINT_MERGE = 1e-9

#: A polygon whose area is below this (m^2) has no interior.
MIN_AREA = 1e-10

#: A contour wider than this (m) is almost certainly not in meters.
MAX_PLAUSIBLE_SIZE = 2.0

#: Cross products below this fraction of the polygon's squared size count as collinear.
COLLINEAR = 1e-12

#: Number of samples of the EFD curve used as its polygon for finger intersection.
EFD_SAMPLES = 256

#: Number of chords an elliptic-arc finger trajectory is split into.
ARC_CHORDS = 16

#: Samples of the ellipse used to turn arc length into angle.
ARC_LENGTH_TABLE = 4096

#: Parallel finger path and contour edge: |cross| below this means no crossing.
PARALLEL = 1e-15

#: Length of a closing direction below which it has no direction.
MIN_DIRECTION = 1e-9

#: Samples of the curvature tables (magnitude, turning sign) used while screening the grid.
#: Building them is a fixed cost of every plan; with the sign interpolated apart, 1024 keeps the
#: screened costs of every example within 1 of the exact ones (4096 in one table: within 38).
CURVATURE_TABLE = 1024

#: Screened poses re-evaluated exactly (at least; 4 x top_k if more).
REFINE_CANDIDATES = 32

#: Distinct best grid poses the continuous refinement starts from (``synthesize(refine=True)``).
REFINE_STARTS = 4

#: Halvings of the refinement's step, from half a grid step: 0.05 m / 2**9 = 0.1 mm, 2 deg / 2**9.
REFINE_HALVINGS = 8

#: Rounds (calls of evaluate_poses, all starts at once) of the refinement at most.
REFINE_ROUNDS = 40

#: Wrench-space zero (wrenches scaled to unit normal force, torque / rho): a Ferrari-Canny
#: epsilon at or below this is no force closure, and a wrench this far outside a plane
#: still counts as on it.
WRENCH_ZERO = 1e-9

#: Three wrenches whose triangle is smaller than this (|cross product|, twice its area; wrenches are
#: of order 1) span no plane: the plane enumeration of the epsilon metric skips them.
WRENCH_PLANE = 1e-12

#: A contact normal shorter than this has no direction.
MIN_NORMAL = 1e-12

#: Adaptive harmonics (efd.choose_harmonics): the fewest and most harmonics it may choose.
#: With 1-2 harmonics the thesis's objects have no concave stretch (thesis 4.2.1, Figure 4.5 a-b).
HARMONICS_BOUNDS = (3, 12)

#: Default of the "rms" rule: RMS distance to the upper-bound model, as a fraction of sqrt(area).
#: Chosen by `python tools/harmonics_figure.py --sweep` (table in efd.choose_harmonics).
HARMONICS_RMS_TOLERANCE = 0.008

#: Default of the "power" rule: share of the first harmonics' power the model may leave out.
HARMONICS_POWER_TOLERANCE = 2e-4

#: Poses checked at once by the finger-thickness test; bounds its (poses, contour points, chords) arrays.
POSE_BATCH = 256
