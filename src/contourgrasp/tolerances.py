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

#: Adaptive harmonics (contour.choose_harmonics): the fewest and most harmonics it may choose.
#: With 1-2 harmonics the thesis's objects have no concave stretch (thesis 4.2.1, Figure 4.5 a-b).
HARMONICS_BOUNDS = (3, 12)

#: Default of the "rms" rule: RMS distance to the upper-bound model, as a fraction of sqrt(area).
#: Chosen by `python tools/harmonics_figure.py --sweep --sim` (docs/studies.md).
HARMONICS_RMS_TOLERANCE = 0.008

#: Default of the "power" rule: share of the first harmonics' power the model may leave out.
HARMONICS_POWER_TOLERANCE = 2e-4

#: Poses checked at once by the finger-thickness test; bounds its (poses, contour points, chords) arrays.
POSE_BATCH = 256


# --- perception ---
from math import radians as _radians  # noqa: E402

#: Working range of the thesis's depth sensor (section 4.1.2), meters.
SENSOR_RANGE = (0.2, 1.5)

#: A pixel belongs to the object when it stands this much (m) above the table.
MIN_HEIGHT = 0.01

#: RANSAC: a point within this distance (m) of a plane is one of its inliers.
PLANE_THRESHOLD = 0.005

#: RANSAC: candidate planes drawn.
PLANE_ITERATIONS = 200

#: RANSAC samples every PLANE_STRIDE-th pixel in both directions (all pixels vote for the final inliers).
PLANE_STRIDE = 4

#: RANSAC scores candidate planes on this many of the points, drawn at random (all of them vote for the refit).
PLANE_SAMPLE = 2000

#: A table holds at least this fraction of the valid depth pixels.
MIN_PLANE_FRACTION = 0.2

#: Planes tilted more than this from facing the camera are walls, not tables (rad).
MAX_TABLE_TILT = _radians(70.0)

#: The bench's camera is tilted at most this far from looking straight down (rad): as oblique as a humanoid's head.
MAX_BENCH_TILT = _radians(65.0)

#: Above this tilt (rad) the contour is planned in the table's plane rather than the image plane.
TILT_PLANE_THRESHOLD = _radians(2.0)

#: Above this tilt (rad) a warning says the top-down assumption is stretched.
TILT_WARN = _radians(20.0)

# The object's footprint on the table (perception.object_footprint).
#: Side of the table grid's cells (m).
FOOTPRINT_CELL = 0.0005
#: The seen points' footprints are joined by closing with a disc of this radius (m): a pixel's width on the table
#: at 1 m with a 525 px focal length, twice over.
FOOTPRINT_CLOSE = 0.004
#: From the first tilt (rad) to the second the footprint's hidden far side is completed by a visual hull whose column
#: grows from infinitely tall (nothing added) to as tall as the object is seen (perception.segment_depth.hidden_side):
#: a band h tan(tilt) behind an object of height h is hidden, 0.58 h at 30 deg. Below, the top seen bounds the far
#: side, and the hull would close the gaps between touching neighbours and the concavities in an object's own
#: shadow. A ramp, not a threshold: a camera near one would get the hull in one frame and not in the next.
HIDDEN_SIDE_TILTS = (_radians(25.0), _radians(35.0))
#: At most this many grid cells (a larger footprint gets coarser cells: the work a frame can ask for is bounded).
FOOTPRINT_MAX_CELLS = 4_000_000

# The support surface (perception.support): a table or a bin's floor.
#: Planes considered, the dominant one included.
SUPPORT_PLANES = 3
#: A further plane holds at least this fraction of the valid depth pixels.
MIN_SUPPORT_FRACTION = 0.05
#: A further plane's normal lies within this angle (rad) of the dominant plane's.
SUPPORT_PARALLEL = _radians(10.0)
#: A candidate stands on a plane when this fraction of the valid pixels in a ring around it lie on the plane ...
SUPPORT_RING_FRACTION = 0.5
#: ... a ring this wide (px).
SUPPORT_RING_PX = 3
#: A hole in an object's mask of at least this many pixels that sees the support surface is object-free.
MIN_TABLE_HOLE_PX = 20
#: A procedural object set (``--objects procedural:N``) holds at most this many objects.
MAX_PROCEDURAL_OBJECTS = 1000
#: ``plan --all`` plans at most this many objects (bounds the work a cluttered frame can ask for).
MAX_ALL_OBJECTS = 16
#: ``plan_any`` (and a clearing run) tries at most this many objects when its own choice has no plan.
MAX_OBJECTS_TRIED = 6

#: Smallest object, in pixels (about 2 x 2 cm at 0.7 m with a 525 px focal length).
MIN_AREA_PX = 200

#: Candidates (perception.find_candidates): raised pixels whose depth differs from a raised 4-neighbour's by more
#: than this (m) are the edge between two surfaces -- an object against a bin's wall -- and may split the raised
#: region there. A steep face seen at the bench's 25 deg tilt changes by about
#: 3 mm a pixel; an object's top against a bin wall's, by centimetres.
CANDIDATE_DEPTH_STEP = 0.02
#: Touching objects (perception.split_touching): two colour clusters of a candidate are two surfaces when their
#: chromaticities (CIELAB a, b on OpenCV's 8-bit scale) lie this far apart ...
TOUCHING_CHROMA = 25.0
#: ... or one's linear luminance is this many times the other's (8-bit values about 1.9 times). Shading on one
#: surface changes it by less on the shared real frames (a mug's or a bottle's lit and shaded parts 1.4 to 2.8 times)
#: except on black objects, whose light is mostly noise (up to 7 times): the surface test below keeps those whole.
TOUCHING_ALBEDO_RATIO = 4.0
#: ... and they are two objects when, in bands this wide (px) on either side of where they meet, the heights within
#: 5 x 5 px of the median pixel span at least this much (m): one lies on or in front of the other. A two-coloured
#: object's parts (a bottle's cap, a drill's grip) meet on one surface: 4 to 8 mm on the shared real frames.
TOUCHING_BAND_PX = 3
TOUCHING_STEP = 0.01
#: ... unless the surface folds outward there (the convexity of Stein et al.'s LCCP, 0 for a step, about 0.7 for a
#: box's top and side): a can's top and its dark side wall seen from above meet at a convex edge.
TOUCHING_CONVEX = 0.3
#: Each piece holds at least this share of the candidate's raised pixels (and ``MIN_AREA_PX``): a printed label's
#: specks are no object (a banana against a heap in a bin is 11 %).
TOUCHING_MIN_SHARE = 0.05
#: A candidate is split into at most this many touching objects (bounds the work of a heap).
MAX_TOUCHING_PIECES = 4
#: A click on the support inside a container means the candidate within this many pixels of it, if one is inside.
CLICK_REACH_PX = 20
#: ... but only where one piece has another at least this fraction inside its filled outline (a bin's walls around an
#: object touching them): an object's own steps, a block on a clamp's body, leave its pieces side by side.
ENCLOSED_FRACTION = 0.5
#: ... or where the region itself closes round at least this much of the support surface (m^2): a container's walls
#: with an object that hides part of them, standing in front of the wall in the view (the bin's floor is 0.12 m^2, a
#: mug handle's or a clamp's hole about 0.001).
CONTAINER_FLOOR_AREA = 0.01

#: A second candidate region at least this fraction of the largest's area draws a warning.
SIMILAR_SIZE = 0.5

#: Colour distance (CIELAB on OpenCV's 8-bit scale) from the table's colour that marks a possible object part.
COLOUR_DISTANCE = 50.0

#: Weight of lightness in that distance: shadows darken the table without changing its hue.
LIGHTNESS_WEIGHT = 0.25

#: A pixel darker than this fraction of the table's CIELAB lightness is object whatever its hue: darker
#: than a soft shadow, which would have to block about 80 % of the light (the table's 8-bit colour x 0.48).
SHADOW_LIGHTNESS = 0.5

#: Colour evidence within this distance (px) of the depth mask is shadow or the object's side;
#: only parts farther out are added to the depth mask.
HALO_PX = 8

#: Colour evidence is opened with a disc of this radius (px) to drop thin straps and specks.
EVIDENCE_OPEN_PX = 2

#: A piece of flat-part evidence of at least ``MIN_AREA_PX`` not touching the object but this close (px) to it
#: is joined to it, by the shortest segment across the gap: a thin part's hinge or neck can look like the table.
FLAT_GAP_PX = 8

#: An image without hue (grey) also takes as evidence the pixels whose height above the table, median-filtered
#: over 5 x 5 pixels, exceeds this many times that filtered height's spread on the table ring around the object
#: (its median absolute deviation scaled to a Gaussian's sigma) ...
FLAT_HEIGHT_SIGMAS = 5.0

#: ... and at least this height (m): a floor for depth without noise.
MIN_FLAT_HEIGHT = 0.0005

#: Colour evidence is first looked for within this distance (px) beyond the table ring around the depth
#: mask; the whole image is searched only when the evidence reaches that window's edge.
FLAT_WINDOW_PX = 96

#: The bench's several attempts and clearing (sim.detect.hand_holds): a closed hand holds something when one of its
#: finger joints reads at least this far (rad, or m for a slide) from where it stops closed on nothing: measured on
#: clutter runs, an empty hand's joints lie within 0.0003 of it and a squeezed object's stop at least 0.02 short ...
HOLD_READING = 0.01
#: ... or when its wrist carries at least this much more than the empty hand, N (2 g; an object caged in the closed
#: hand, every finger at its limit, still weighs: the bench's 12 g toy airplane 0.12 N, the empty hand 0.000).
HOLD_LOAD = 0.02
#: A hand is read once no finger joint turns faster than this, rad/s (sim.scene.Scene.hand_reading): a finger still
#: closing is not yet stopped by anything.
HOLD_SPEED = 0.01
#: At most this many attempts per trial (bounds the work a bench can ask for).
MAX_ATTEMPTS = 5

#: A memory of failed grasps (synthesis.memory) excludes the poses within this distance (m) of a failure mapped into
#: the object's frame: a search grid step and a half (1 cm steps), so that the next plan is not the failure again ...
MEMORY_REACH = 0.015
#: ... and within this turn of its yaw (rad): five of the default grid's 4 deg steps.
MEMORY_TURN = _radians(20.0)
#: An outline whose two principal second moments differ by less than this share of the larger has no axis that turns
#: with it (a can seen from above: its frame keeps the planning frame's orientation).
MEMORY_ROUND = 0.1
#: A memory keeps at most this many failures, the oldest dropped first (bounds the work a memory can ask for).
MAX_MEMORY_FAILURES = 32
#: A scene's memory (synthesis.SceneMemory) finds an object again where it is seen within this many pixels of where
#: it was seen at its last failure (a failed grasp moves it a little) ...
MEMORY_SAME_OBJECT_PX = 20
#: ... and keeps at most this many objects, the one that failed longest ago dropped first.
MAX_MEMORY_OBJECTS = 32

#: The distance over which ``Safeguards.centring_gain`` costs its gain once, m (``synthesis.cost.centring_distance``).
CENTRING_SCALE = 0.01

#: The largest ``centring_gain``: the term stays finite and printable (d^2 / CENTRING_SCALE^2 is 1e4 for a metre of
#: distance), and 1e6 already outweighs every other part of the cost by orders of magnitude.
MAX_CENTRING_GAIN = 1e6

#: A target pixel on a low-lying part (below ``MIN_HEIGHT``, above the table's noise) is followed to the
#: candidate it belongs to within this distance, pixels (``perception.candidates.low_part_candidate``):
#: the YCB fork, seen from the bench's camera, is 150-170 px long, its raised pieces at either end.
LOW_PART_REACH_PX = 128

#: ... into a candidate's raised pixels that stand at most this much above ``MIN_HEIGHT`` next to it (m):
#: a part rises into its own object; a neighbour it only touches stands up sharply beside it.
LOW_PART_STEP = 0.01

#: Largest colour-depth misregistration searched for, pixels in each direction.
MAX_COLOUR_OFFSET_PX = 8

#: Most pixels of an image read or planned on (25 MP: above every depth camera's and most colour cameras'):
#: a larger one is refused before it is decoded, not after it has filled the memory.
MAX_IMAGE_PIXELS = 25_000_000

#: Focal lengths accepted in intrinsics, pixels: a lens of any field of view below 175 deg on an image of at most
#: ``MAX_IMAGE_PIXELS`` lies well inside.
FOCAL_RANGE_PX = (1.0, 1e6)

#: The colour-depth registration compares edges over the object's bounding box grown by this, pixels.
REGISTRATION_MARGIN_PX = 20

#: Holes in the depth image up to this many pixels are filled.
MAX_HOLE_PX = 400

#: Tolerance (px) of the polygon simplification of the mask outline.
CONTOUR_EPSILON_PX = 0.75

#: At most this many points of a mask's outline (perception's pixel contour), so that O(n^2) checks
#: downstream stay cheap. (``MAX_CONTOUR_POINTS`` below is the bound of any contour the planner takes.)
MAX_OUTLINE_POINTS = 400

#: Offset added to the minimum depth for the approach depth (section 3.1.1), m.
APPROACH_OFFSET = 0.01

#: The minimum depth for the approach is taken after a median filter of this size (px): the minimum of
#: raw readings rides on their noise (about 5 mm nearer than the object's top with the simulated sensor's
#: 2 mm at 0.7 m, 2 mm after the filter) and on single flying pixels; features 2 px wide survive it.
APPROACH_MEDIAN_PX = 3

#: Height map (perception.height_map): side of a cell, m. 2 mm is about one and a half depth pixels at
#: the working distance (1.3 mm at 0.7 m with a 525 px focal length), so nearly every cell holds a reading,
#: and a fifth of the simulated fingers' 9 mm radius.
HEIGHT_MAP_CELL = 0.002

#: Height map: the grid reaches this far (m) beyond the object's contour on every side, at least the
#: hand's reach (the presets' fingertips start at most 0.1 m from the reference point, the simulated
#: fingers' knuckles lean 3-5 cm further), so every cell a planned pose's fingers pass over is in it.
HEIGHT_MAP_MARGIN = 0.20

#: The scene seen along a side or tilted approach (perception.view_along): a cell's side, in the height map's
#: cells (a cell's diagonal, so that columns seen slantwise leave no gap between them; the columns are sampled as
#: finely), and how far (m) its grid reaches beyond the target's outline and its check of the hand's way reaches
#: in front of the target: the hand's reach.
VIEW_CELL = 2.0 ** 0.5
VIEW_MARGIN = 0.15

#: Height map: raised cells within this distance (m) of the object's contour or mask points belong to the
#: object too: the mask's outermost pixels and the contour through their centres stop up to a few pixels
#: short of the object's edge (the footprint of a tilted camera misses 1-3 px on the object's far side).
HEIGHT_MAP_OBJECT_BAND = 0.006

#: Height map: a cell stands up (an obstacle) only within this many cells of one where a reading's 3 x 3
#: median stands ``MIN_HEIGHT`` up too: a lone noisy reading on the table is no wall, an object's edge
#: keeps its highest readings.
STEADY_REACH_CELLS = 2

#: Height map: an unseen cell that no seen surface can have hidden (a dropout beside an edge, speckle) and that lies
#: within this distance (m) of seen cells is bounded by the highest of them; farther inside a hole, by the map's
#: highest seen height. Edge dropouts and speckle leave holes a few millimetres wide.
HOLE_BORDER_REACH = 0.006

#: Height map: the largest cell (m) and margin (m) accepted; beyond them a value is a unit slip.
MAX_HEIGHT_MAP_CELL = 0.1
MAX_HEIGHT_MAP_MARGIN = 2.0

#: Height map: most cells. 4 M cells of float64 heights and two bool masks are about 40 MB; the default
#: map of a 15 cm object is 275 x 275 = 76 k cells. A cell so small that the grid would exceed this is refused.
MAX_HEIGHT_MAP_CELLS = 4_000_000

#: A pixel ray meeting the planning plane at a cosine below this is refused as grazing.
MIN_RAY_COSINE = 0.05

#: Plausible bounds of the approach offset (|offset|, m) and of the pre-grasp standoff (m): a hand
#: placed half a meter beyond or short of the object's top, or pulled back 2 m, is a typo (a unit
#: slip, a sign), not a plan.
MAX_APPROACH_OFFSET = 0.5
MAX_STANDOFF = 2.0

#: Largest deviation of R^T R from I, and of det R from 1, accepted in a rigid transform (T_base_camera).
#: 1e-5 rather than 1e-6: a rotation printed with 6 decimals, as in the autolab
#: ``.tf`` files, is off by up to about 1.5e-6 (the shared primesense.tf by 1.02e-6).
ROTATION_TOLERANCE = 1e-5

#: Largest deviation of a unit vector's length from 1 (a plane's normal given by a user), as for rotations.
UNIT_TOLERANCE = ROTATION_TOLERANCE

#: Largest deviation of a rigid transform's last row from 0 0 0 1.
HOMOGENEOUS_ROW = 1e-9


# --- sim ---

#: A mesh whose largest extent exceeds this (m) is taken to be in millimetres.
#: Most triangles of an object's mesh: the YCB meshes have 16,384; a denser one costs minutes a trial in the
#: convex decomposition and the contacts, and is refused naming the file.
MESH_MAX_FACES = 100_000
MESH_MAX_EXTENT = 1.0

#: A mesh whose vertices all lie within this fraction of its size from its convex hull is convex enough
#: to collide as its hull.
MESH_CONVEX = 0.02

#: A simulated fingertip this close to its full travel counts as closed, m: the soft joint limit lets it creep the rest.
CLOSED_WITHIN = 5e-4

#: A simulated fingertip that has travelled this far has started to move, m.
FINGER_MOVED = 1e-3

#: Longest closing or hold of a hand model in free air (derive.derive_hand, force.fingertip_forces), s:
#: a bound on the simulation an argument can ask for (the defaults are 1-3 s).
MAX_MODEL_CLOSING_TIME = 60.0

#: Most bodies of a MuJoCo hand model read (a hand on an arm has well under a hundred): a larger model is refused
#: before it is closed, as not a hand.
MAX_MODEL_BODIES = 300

#: force.fingertip_forces: a fingertip slower than this has no direction of motion to push along
#: (stopped at a joint limit, say), m/s; a 3 s closing moves the bundled models' tips at 20-40 mm/s.
FINGERTIP_MOVING = 1e-3

#: Closing times closer than this are a tie when calibrate chooses the reference finger (half a 2 ms step), s.
CLOSING_TIE = 1e-3

#: Contact distances per finger in calibrate's average over its travel (trapezoidal rule).
TRAVEL_SAMPLES = 1001


# --- contour ---

#: A contour wider than this (m) is refused: no hand grasps it, even read as millimetres (a 10 m object),
#: and far below it nothing derived from it (area, perimeter, the search grid) can overflow.
MAX_CONTOUR_SIZE = 1e4

#: A contour narrower than this (m) is refused: a tenth of a millimetre, far below a camera pixel at
#: working distance (about 1.5 mm) and anything a hand grasps. At this width a polygon with less than
#: MIN_AREA is a sliver a micrometre thick: "collinear" is then the right word for it.
MIN_CONTOUR_SIZE = 1e-4

#: A contour with more points than this is resampled uniformly by arc length to this many (a 1 m outline
#: every 0.1 mm): the self-intersection test is O(n^2) and takes about 0.1 s at this size.
MAX_CONTOUR_POINTS = 10_000

#: Most harmonics an EFD may have (eq 3.3-3.4): far above any count worth fitting (the adaptive rule
#: stops at HARMONICS_BOUNDS[1]), and the fit's (harmonics, points) arrays stay a few MB.
MAX_HARMONICS = 100

#: Two edges leaving one vertex at angles closer than this (rad) run along each other: where a contour
#: passes twice through a point, such a pass touches the other rather than crossing it.
SAME_DIRECTION = 1e-12


# --- synthesis ---

#: Largest friction coefficient accepted (quality metrics, Safeguards.friction): no real pair of
#: materials reaches 10 (rubber on rubber is about 1-2), and far beyond it the friction cones' edges
#: swamp their normals until Qhull fails on the wrench hull.
MAX_FRICTION = 10.0

#: Largest length of a hand (m): a finger's start, travel, virtual start, radius and an arc's radii.
#: No hand the planner is meant for spans 2 m; beyond it a value is a unit slip (mm for m), and far
#: beyond it the search's arithmetic over- or underflows.
MAX_HAND_SIZE = 2.0

#: Largest |phi_off| of an elliptic-arc finger (rad): any start angle is within 2 pi of one below
#: this, and far beyond it cos and sin lose every digit of the angle.
MAX_ARC_ANGLE = 100.0

#: Largest length of the search (m): grid step, D_max, D_min and the safeguards' clearance. A
#: hand is at most MAX_HAND_SIZE, so poses farther from the object than this reach nothing.
MAX_SEARCH_LENGTH = 10.0

#: Most poses of a search grid. The screen keeps about 0.4 kB per pose for a five-finger hand
#: (contacts, parameters, curvature, distances, costs), so this bounds it to a few hundred MB;
#: the `default` planner's grid has 172,980 poses and the dense bench case 345,960.
MAX_GRID_POSES = 1_000_000

#: Most rounds of the continuous refinement (refine_poses(rounds=...)); REFINE_ROUNDS is the default.
REFINE_MAX_ROUNDS = 1000

#: Largest magnitude of a hand's cost gains (alpha, beta, miss_penalty): the presets' largest is 1e4,
#: and far beyond it a sum of costs overflows to inf (and inf - inf to NaN).
MAX_GAIN = 1e9

#: The L-inf wrench space (quality metric "Linf") has 3**n vertices before the hull; beyond this
#: many contacts it is refused.
LINF_MAX_CONTACTS = 8

#: Most fingers of a hand: every array of the search has one column per finger (about 65 bytes per
#: pose and finger on the grid), and no hand the planner is meant for has more fingertips.
MAX_FINGERS = 10

#: A finger's 3-D chain must agree with its 2-D trajectory to this distance (m): its open tip,
#: projected on the palm plane, within it of ``start``, its closed tip within it of the trajectory's
#: end, and the projected tip path within it of the trajectory all along (hand.check_chain).
CHAIN_TRAJECTORY = 1e-3

#: A palm's underside given by its vertices' depths must be planar to this (m): the descent check takes
#: the plane through them.
PALM_PLANARITY = 1e-4

#: Most samples (closing progresses) of a hand.SampledChain, and most points per sample (knuckle, further
#: joints, tip): a measured chain is checked and swept sample by sample, so its size bounds the work.
MAX_CHAIN_SAMPLES = 201
MAX_CHAIN_POINTS = 8

#: Samples of a chain measured on a hand model (handmodels.derive): evenly in the tip's travel, close
#: enough that the linear interpolation between them stays within a few hundredths of a millimetre
#: of the arcs the bundled models' tips follow.
MODEL_CHAIN_SAMPLES = 41

#: Closing progresses s in [0, 1] at which hand.check_chain compares a chain's tip with its 2-D path.
CHAIN_SAMPLES = 201

#: Vertices of the polyline an arc trajectory is compared against by hand.check_chain (its chords
#: are within a few micrometres of the arc for the presets' sizes).
CHAIN_ARC_VERTICES = 1025

#: Largest |joint angle| of a finger chain (rad): a link turned more than half a turn from the
#: approach axis is a sign or unit slip (degrees for radians).
MAX_JOINT_ANGLE = 3.141592653589793

# --- depth images (camera files and ROS messages) ---

#: A median depth above this (m) is almost certainly not in meters.
MAX_PLAUSIBLE_DEPTH = 20.0

#: A median depth below this (m) is closer than any depth camera measures.
MIN_PLAUSIBLE_DEPTH = 0.02

# --- the 3-D hand in the search ---

#: Descent check in the search: the clearance (m) every body of the open hand keeps over the height map.
#: 3 mm covers the map's discretisation (a body moved by half a 2 mm cell's diagonal, 1.4 mm) and the
#: sensor's noise on a surface's height (about 1 mm at the working distance).
DESCENT_MARGIN = 0.003

#: Descent check in the search: candidate poses checked at once, in increasing cost (the best pose found is the
#: same for any batch; 8 rather than 32: most plans find it in the first batch, about 8 ms less on the bundled
#: frame), and the most checked in one search before it gives up (0.1-0.4 ms a pose: at most about 2 s).
DESCENT_BATCH = 8
MAX_DESCENT_POSES = 4096

#: Grasp height rule "clearance" (synthesis.grasp_height): the open fingertips' surfaces this far (m) above the
#: table, and the palm's underside at least this far above the object's top -- the simulated execution's own
#: rule before the planner chose the height (sim.trial.Execution's tip_clearance and palm_clearance).
GRASP_TIP_CLEARANCE = 0.003
GRASP_PALM_CLEARANCE = 0.02

#: Grasp height rule "auto": the grasp height asked for, and the highest accepted where the hand's bodies need
#: it higher, as fractions of the object's height. Chosen on ycb-train and the thesis's five
#: (docs/studies.md).
GRASP_HEIGHT_FRACTION = 0.4
MAX_GRASP_HEIGHT_FRACTION = 0.7

#: perception.cross_section: fewer object cells than this standing at the grasp height (m^2 / cell^2: 50 cells of
#: 2 mm are 2 cm^2) is no section: the fingertips would close under the object's top on almost nothing.
MIN_SECTION_CELLS = 50

#: The squeeze's balance (synthesis.Safeguards.max_imbalance) is screened on the grid's polygon contacts: poses
#: within this much of max_imbalance there are evaluated exactly (the exact contacts move the normals by less).
#: Against no screen at all, ycb-train's 84 bench trials (seeds 0-3) and ycb's 410 were the same, trial for trial.
IMBALANCE_SCREEN = 0.05

#: A hand's own max_imbalance (Hand.max_imbalance, the planner option's "hand") when its file states none. Chosen
#: on the five-finger hand's ycb-train and thesis's-five trials (docs/studies.md); on the three-finger
#: preset's it ties with 1/3.
HAND_MAX_IMBALANCE = 0.25

#: The small-object rule (pipeline.plan_frame(small_objects=True)): the fewest touching fingers it plans with (at
#: least the hand's required ones): the thumb against one finger. Chosen on ycb-train (docs/hand3d.md): with
#: three, the strawberry still had no plan.
SMALL_OBJECT_TOUCHING = 2

#: The low-object rule (pipeline.plan_frame(low_objects=True)): an object whose top (HeightMap.max_height) is lower
#: than this (m) is planned first as a pinch with the fingertips as balls (synthesis.search(low_object=True)). Chosen
#: on ycb-train, in the gap between its objects' heights: the rule lifted the medium clamp (27 mm) and the Lego brick
#: (24 mm); the next, the gelatin box and the tuna can (32-35 mm), were lifted every time without it (at 36 mm
#: ycb-train is the same, at 25 mm the clamp leaves the rule and two trials are lost: docs/studies.md).
LOW_OBJECT_HEIGHT = 0.03

#: Chords per quarter circle of the arcs contour.grow_polygon puts at convex corners (shapely's quad_segs): a 9 mm
#: fingertip's arc deviates from its chords by 9 mm x (1 - cos(pi / 32)) = 0.04 mm.
GROWTH_ARC_SEGMENTS = 8
#: contour.grow_polygon resamples a polygon of more points than this by arc length first: shapely's buffer of a
#: jagged 500-point star takes 0.4 s, of 2,000 points 11 s; an object small enough for the growth to be needed
#: (a few cm across) is then outlined every 0.3 mm or finer.
MAX_GROWTH_POINTS = 500

#: Closing sweep (synthesis.sweep): closing progresses sampled per finger, and how much earlier than its tip's ball
#: (radius + this, m) a finger's chain may meet the object before the pose counts as "a link touches first".
SWEEP_SAMPLES = 12
SWEEP_TOLERANCE = 0.005

#: A capsule axis with 1 - u_z^2 below this is vertical (synthesis descent and sweep kernels): its lowest points
#: on a vertical line are its end balls'.
VERTICAL_AXIS = 1e-12


# --- hand models (handmodels.derive) ---

#: Largest distance (m) of a MuJoCo model's fingertip path, projected on the palm plane, from the ray or
#: elliptic arc fitted to it; a finger fitting neither within this is refused by hand-from-model.
MODEL_FIT_TOLERANCE = 3e-3
# --- simulated scenes of several objects ---

#: A neighbour whose centre of mass rose more than this (m) during a grasp was lifted with the target.
NEIGHBOUR_LIFT = 0.02
#: A target that sank more than this (m) from the lift's start to the hold's end left the table: the scene has no
#: floor, so it fell for the seconds of the lift and hold (the trials' figure says so rather than a depth).
FELL_OFF_TABLE = 0.5

#: The bench (sim.bench.Bench): trials per object and planner, trials in all (objects x trials x planners; at about a
#: second a trial per core, a day's work on a small cluster), and the largest first seed (numpy's seeds are unbounded;
#: a bench's are kept to 31 bits so that seed + trial stays a plain integer everywhere).
MAX_TRIALS = 1000
MAX_BENCH_TRIALS = 100_000
MAX_SEED = 2**31 - 1 - MAX_TRIALS

# --- contourgrasp doctor: what looks wrong in a user's frame ---

#: A missing reading within this many pixels of a depth jump of more than DOCTOR_EDGE_STEP (m) is the sensor's
#: (a projector's shadow, a flying-pixel filter), not the scene's.
DOCTOR_EDGE_PX = 3
DOCTOR_EDGE_STEP = 0.02
#: More of the depth missing than this share is flagged.
DOCTOR_MAX_MISSING = 0.3
#: Horizontal and vertical fields of view (deg) a depth camera has; outside, the intrinsics are probably another
#: image size's.
DOCTOR_FOV_DEG = (20.0, 130.0)
#: A principal point further than this share of the image size from its centre is flagged.
DOCTOR_CENTRE_SHARE = 0.15
#: A colour-depth offset of more pixels than this on the target is flagged.
DOCTOR_MAX_OFFSET_PX = 4
