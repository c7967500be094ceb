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

#: Samples of the curvature table used while screening the grid.
CURVATURE_TABLE = 4096

#: Screened poses re-evaluated exactly (at least; 4 x top_k if more).
REFINE_CANDIDATES = 32

#: Poses evaluated at once; bounds the memory of the (poses, segments, edges) arrays.
POSE_CHUNK = 256
