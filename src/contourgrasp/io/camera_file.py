"""Camera files: colour and depth images, masks, intrinsics and extrinsics.

Formats read
------------
Colour
    Anything OpenCV reads (PNG, JPG, ...); returned in RGB order, uint8.
Depth
    ``.npy`` float: meters, as is. ``.npy`` integer, 16-bit ``.png``: raw
    units times ``depth_scale`` (default 0.001, millimetres, as most
    RGB-D drivers write). Float ``.tif``/``.tiff``: meters. A trailing
    channel of 1 ((H, W, 1), as in the gqcnn files) is squeezed. 0 and NaN
    mean "no reading" and are kept.
Mask
    Any image or ``.npy``; non-zero pixels (in any channel) are object.
Intrinsics (JSON ``.json``/``.intr``, or YAML ``.yaml``/``.yml``)
    * plain: ``{fx, fy, cx, cy, width, height}``;
    * ROS camera_info: ``camera_matrix: {data: [9 numbers]}`` with
      ``image_width``/``image_height`` (calibration YAML), or ``K``/``k`` (9
      numbers) with ``width``/``height`` (CameraInfo message);
    * BerkeleyAutomation ``.intr``: ``{_fx, _fy, _cx, _cy, _width, _height}``.
Extrinsics: T_base_camera, the 4 x 4 rigid transform taking camera-frame points to the base frame
    ``.npy`` or ``.txt`` (4 x 4 numbers); JSON/YAML holding a 4 x 4 list, or a
    mapping with ``matrix`` (4 x 4) or ``rotation`` (3 x 3) and ``translation``
    (3); autolab ``.tf`` (line 1 from-frame, line 2 to-frame, line 3
    translation, lines 4-6 rotation rows; camera to world).

Every problem is an :class:`~contourgrasp.errors.InputError` whose one-line
message names the file (and the field).
"""

from __future__ import annotations

import json
import math
import os
import warnings
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path

import cv2
import numpy as np

from .. import tolerances as tol
from .. import validation
from ..errors import DepthUnitWarning, InputError
from ..perception import Intrinsics
from ..perception.camera import check_colour_size
from ..tolerances import HOMOGENEOUS_ROW, ROTATION_TOLERANCE

#: Default raw-unit size of integer depth images, m (millimetres).
DEPTH_SCALE = 0.001


__all__ = [
    "DEPTH_SCALE", "Intrinsics", "RGBDFrame", "read_depth", "read_extrinsics", "read_intrinsics", "read_mask",
    "read_rgb", "read_rgbd",
]


@dataclass(frozen=True, eq=False)
class RGBDFrame:
    """One frame: the images that were given, checked to have the intrinsics' size.

    Attributes
    ----------
    rgb : (H, W, 3) uint8 or None
        Colour, RGB order.
    depth : (H, W) float or None
        Depth in meters, 0 or NaN where missing.
    intrinsics : Intrinsics or None
        Of the depth image.
    mask : (H, W) bool or None
        The user's object mask (:func:`read_mask`), when one was given.
    colour_intrinsics : Intrinsics or None
        The colour camera's, when the intrinsics file gives them (``color_fx``, ... ``color_height``):
        a colour image at another resolution than the depth is resampled with them
        (:func:`contourgrasp.perception.colour_on_depth`).
    """

    rgb: np.ndarray | None
    depth: np.ndarray | None
    intrinsics: Intrinsics | None
    mask: np.ndarray | None = None
    colour_intrinsics: Intrinsics | None = None


def read_rgb(path) -> np.ndarray:
    """(H, W, 3) uint8: a colour image in RGB order (grayscale files are expanded)."""
    image = _read_image(path, cv2.IMREAD_COLOR)
    return cv2.cvtColor(image, cv2.COLOR_BGR2RGB)


def read_mask(path) -> np.ndarray:
    """(H, W) bool: a mask image or ``.npy``; non-zero in any channel is object, and some pixel must be."""
    path = Path(path)
    data = _load_npy(path) if path.suffix.lower() == ".npy" else _read_image(path, cv2.IMREAD_UNCHANGED)
    if data.ndim == 3:
        data = np.any(data != 0, axis=2)
    if data.ndim != 2:
        raise InputError(f"{path}: a mask must be a 2-D image, got shape {data.shape}")
    mask = np.nan_to_num(data.astype(float)) != 0
    if not mask.any():
        raise InputError(f"{path}: the mask is empty (no non-zero pixel marks the object)")
    return mask


def read_depth(path, *, depth_scale: float = DEPTH_SCALE) -> np.ndarray:
    """Read a depth image in meters.

    Parameters
    ----------
    path : str or Path
        ``.npy``, 16-bit ``.png`` or float ``.tif``/``.tiff`` (module docstring).
    depth_scale : float
        Meters per raw unit of integer images.

    Returns
    -------
    (H, W) float
        Meters; 0 or NaN where there is no reading.

    Raises
    ------
    InputError
        Missing or unreadable file, wrong shape or type, no valid pixel.

    Warns
    -----
    DepthUnitWarning
        When the median reading is implausible in meters (e.g. millimetres); a :class:`UnitWarning`.
    """
    path = Path(path)
    if isinstance(depth_scale, bool) or not isinstance(depth_scale, (int, float)) or not 0 < depth_scale < math.inf:
        raise InputError(f"depth_scale must be a positive number, got {depth_scale!r}")
    raw = _load_npy(path) if path.suffix.lower() == ".npy" else _read_image(path, cv2.IMREAD_UNCHANGED)
    if raw.ndim == 3 and raw.shape[2] == 1:
        raw = raw[..., 0]
    if raw.ndim != 2:
        raise InputError(f"{path}: depth must be one channel (H, W) or (H, W, 1), got shape {raw.shape}")
    if np.issubdtype(raw.dtype, np.floating):
        depth = raw.astype(float)
    elif np.issubdtype(raw.dtype, np.integer) and raw.dtype.itemsize >= 2:
        depth = raw.astype(float) * depth_scale
    else:
        raise InputError(f"{path}: depth of type {raw.dtype} (need float meters, or 16-bit or wider integers)")
    present = depth[np.isfinite(depth) & (depth > 0)]
    if present.size == 0:
        raise InputError(f"{path}: depth has no valid pixel (all zero, negative or NaN)")
    _check_depth_unit(path, float(np.median(present)), np.issubdtype(raw.dtype, np.integer))
    return depth


#: The scales of the integer depth units cameras store (meters per unit), for the unit a depth seems to be in.
MILLIMETRE, TENTH_MILLIMETRE = 0.001, 0.0001


def _check_depth_unit(path, median, scaled):
    if median > tol.MAX_PLAUSIBLE_DEPTH:
        if median * MILLIMETRE <= tol.MAX_PLAUSIBLE_DEPTH:
            unit = "probably millimetres (scale 0.001)"
        elif median * TENTH_MILLIMETRE <= tol.MAX_PLAUSIBLE_DEPTH:
            unit = "probably tenths of millimetres (scale 0.0001)"
        else:  # 1e300 from a corrupt file: naming a scale would send the user looking for the wrong fix
            unit = "no depth camera's unit makes that a distance it measures"
        diagnosis = f"median depth {median:.4g} m: {unit}"
    elif median < tol.MIN_PLAUSIBLE_DEPTH:
        diagnosis = f"median depth {median:.4g} m is closer than a depth camera measures (already scaled twice?)"
    else:
        return
    warnings.warn(DepthUnitWarning(path, diagnosis, scaled), stacklevel=3)


def read_intrinsics(path) -> Intrinsics:
    """Read camera intrinsics (plain, ROS camera_info, or BerkeleyAutomation ``.intr``; module docstring)."""
    path = Path(path)
    data = _read_mapping(path)
    if not isinstance(data, dict):
        raise InputError(f"{path}: intrinsics must be a mapping of fields, got {type(data).__name__}")
    if "_fx" in data:
        fields = {name: _field(path, data, f"_{name}") for name in ("fx", "fy", "cx", "cy", "width", "height")}
    elif any(key in data for key in ("camera_matrix", "K", "k")):
        fields = _ros_fields(path, data)
    else:
        fields = {name: _field(path, data, name) for name in ("fx", "fy", "cx", "cy", "width", "height")}
    try:
        return Intrinsics(**fields)
    except InputError as err:
        raise InputError(f"{path}: {err}") from None


#: The keys of a colour camera's own intrinsics in an intrinsics file, beside the depth camera's.
COLOUR_KEYS = ("fx", "fy", "cx", "cy", "width", "height")


def read_colour_intrinsics(path) -> Intrinsics | None:
    """The colour camera's intrinsics an intrinsics file gives beside the depth camera's (``color_fx``, ``color_fy``,
    ``color_cx``, ``color_cy``, ``color_width``, ``color_height``; ``colour_`` too), or None when it gives none."""
    path = Path(path)
    data = _read_mapping(path)
    if not isinstance(data, dict):
        return None
    for prefix in ("color_", "colour_"):
        if any(prefix + key in data for key in COLOUR_KEYS):
            fields = {key: _field(path, data, prefix + key) for key in COLOUR_KEYS}
            try:
                return Intrinsics(**fields)
            except InputError as err:
                raise InputError(f"{path}: colour {err}") from None
    return None


def _ros_fields(path, data) -> dict:
    if "camera_matrix" in data:
        matrix = _field(path, data, "camera_matrix")
        if not isinstance(matrix, dict):
            raise InputError(f"{path}: field camera_matrix must be a mapping with data: [9 numbers]")
        k, k_name = _field(path, matrix, "data", "camera_matrix.data"), "camera_matrix.data"
        width, height = _field(path, data, "image_width"), _field(path, data, "image_height")
    else:
        k_name = "K" if "K" in data else "k"
        k = data[k_name]
        width, height = _field(path, data, "width"), _field(path, data, "height")
    k = _numbers(path, k, k_name, (9,))
    return {"fx": k[0], "fy": k[4], "cx": k[2], "cy": k[5], "width": width, "height": height}


def read_extrinsics(path) -> np.ndarray:
    """Read T_base_camera, a 4 x 4 rigid transform (formats in the module docstring).

    Returns
    -------
    (4, 4) float
        p_base = T @ [p_camera, 1]. The rotation is re-orthonormalised (nearest
        rotation), so it is exact even when the file rounded it.

    Raises
    ------
    InputError
        Unreadable file, wrong shape, or not rigid: R^T R or det R off by more
        than ``ROTATION_TOLERANCE``, or a last row other than 0 0 0 1.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".tf":
        matrix = _read_tf(path)
    elif suffix == ".npy":
        matrix = _numbers(path, _load_npy(path), "matrix", (4, 4))
    elif suffix == ".txt":
        matrix = _numbers(path, _read_text(path).split(), "matrix", (16,)).reshape(4, 4)
    else:
        matrix = _mapping_transform(path, _read_mapping(path))
    return _check_rigid(path, matrix)


def _read_tf(path) -> np.ndarray:
    lines = [line for line in _read_text(path).splitlines() if line.strip()]
    if len(lines) != 6:
        raise InputError(
            f"{path}: a .tf file has 6 lines (from-frame, to-frame, translation, 3 rotation rows), got {len(lines)}"
        )
    translation = _numbers(path, lines[2].split(), "translation (line 3)", (3,))
    rotation = _numbers(path, " ".join(lines[3:]).split(), "rotation (lines 4-6)", (9,)).reshape(3, 3)
    return _homogeneous(rotation, translation)


def _mapping_transform(path, data) -> np.ndarray:
    if isinstance(data, list):
        return _numbers(path, data, "matrix", (4, 4))
    if not isinstance(data, dict):
        raise InputError(f"{path}: expected a 4 x 4 list or a mapping, got {type(data).__name__}")
    if "matrix" in data:
        return _numbers(path, data["matrix"], "matrix", (4, 4))
    if "rotation" in data or "translation" in data:
        rotation = _numbers(path, _field(path, data, "rotation"), "rotation", (3, 3))
        translation = _numbers(path, _field(path, data, "translation"), "translation", (3,))
        return _homogeneous(rotation, translation)
    raise InputError(f"{path}: missing field matrix (or rotation and translation)")


def _homogeneous(rotation, translation) -> np.ndarray:
    matrix = np.eye(4)
    matrix[:3, :3], matrix[:3, 3] = rotation, translation
    return matrix


def _check_rigid(path, matrix) -> np.ndarray:
    validation.rigid_transform(str(path), matrix, rotation_tolerance=ROTATION_TOLERANCE,
                               row_tolerance=HOMOGENEOUS_ROW)
    u, _, vt = np.linalg.svd(matrix[:3, :3])
    out = matrix.copy()
    out[:3, :3] = u @ vt
    return out


#: The files a frame folder's colour, depth and intrinsics are looked for in, in this order.
FRAME_FILES = {"colour": ("color*.png", "colour*.png", "rgb*.png", "*color*.png", "*rgb*.png", "*.jpg"),
               "depth": ("depth*.npy", "*depth*.npy", "depth*.png", "*depth*.png"),
               "intrinsics": ("camera.yaml", "camera_info.yaml", "*.intr", "camera*.json", "intrinsics*", "*.yaml")}


def frame_files(folder) -> tuple[Path, Path, Path]:
    """The colour image, depth image and intrinsics file of a folder holding one frame (:data:`FRAME_FILES`).

    Raises
    ------
    InputError
        Not a folder, or one of the three is not in it.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise InputError(f"{folder}: not a folder (give a folder holding one frame, or --rgb, --depth, --intrinsics)")
    found = {}
    for kind, patterns in FRAME_FILES.items():
        found[kind] = next((p for pattern in patterns for p in sorted(folder.glob(pattern)) if p.is_file()), None)
        if found[kind] is None:
            raise InputError(f"{folder}: no {kind} file ({', '.join(patterns)})")
    return found["colour"], found["depth"], found["intrinsics"]


def read_rgbd(rgb_path=None, depth_path=None, intrinsics_path=None, *, mask_path=None,
              depth_scale: float = DEPTH_SCALE) -> RGBDFrame:
    """Read the files of one frame and check their sizes agree.

    Any of them may be None; depth needs intrinsics.

    Raises
    ------
    InputError
        From the readers, depth without intrinsics, or two sizes that differ
        (the message gives both files and both sizes).
    """
    if depth_path is not None and intrinsics_path is None:
        raise InputError(f"{depth_path}: a depth image needs an intrinsics file")
    rgb = None if rgb_path is None else read_rgb(rgb_path)
    depth = None if depth_path is None else read_depth(depth_path, depth_scale=depth_scale)
    intrinsics = None if intrinsics_path is None else read_intrinsics(intrinsics_path)
    colour_intrinsics = None if intrinsics_path is None else read_colour_intrinsics(intrinsics_path)
    mask = None if mask_path is None else read_mask(mask_path)
    scaled = rgb is not None and depth is not None and rgb.shape[:2] != depth.shape[:2]
    sized = [(p, a.shape) for p, a in ((None if scaled else rgb_path, rgb), (depth_path, depth), (mask_path, mask))
             if a is not None and p is not None]
    if intrinsics is not None:
        sized.append((intrinsics_path, intrinsics.shape))
    for (path_a, shape_a), (path_b, shape_b) in zip(sized, sized[1:]):
        if shape_a[:2] != shape_b[:2]:
            raise InputError(
                f"{path_a} is {shape_a[1]}x{shape_a[0]} but {path_b} is {shape_b[1]}x{shape_b[0]} (width x height)"
            )
    if scaled:  # colour at another resolution: the same view scaled, or mapped by the colour intrinsics
        try:
            check_colour_size(rgb.shape, depth.shape, intrinsics=None if colour_intrinsics is None else intrinsics,
                              colour_intrinsics=colour_intrinsics)
        except InputError as err:
            raise InputError(f"{rgb_path}: {err} ({intrinsics_path} gives no color_fx, ...)"
                             if colour_intrinsics is None else f"{rgb_path}: {err}") from None
    return RGBDFrame(rgb=rgb, depth=depth, intrinsics=intrinsics, mask=mask, colour_intrinsics=colour_intrinsics)


def read_masked_frames(root):
    """Every frame with a mask below ``root`` in the Dex-Net layout, in name order: (name, :class:`RGBDFrame`).

    A frame is a folder's ``color_N.png``, ``depth_N.npy`` (meters) and ``segmask_N.png``, with the folder's
    first ``*.intr`` file (the layout of ``examples/bar_clamp`` and of the GQ-CNN datasets); its name is
    ``<folder>/N``. A mask without its depth image or a folder without intrinsics is passed over.

    Raises
    ------
    InputError
        A frame's files that cannot be read (naming the file).
    """
    for mask_path in sorted(Path(root).glob("*/segmask_*.png")):
        folder, index = mask_path.parent, mask_path.stem.removeprefix("segmask_")
        intrinsics = sorted(folder.glob("*.intr"))
        if intrinsics and (folder / f"depth_{index}.npy").is_file():
            yield f"{folder.name}/{index}", read_rgbd(folder / f"color_{index}.png", folder / f"depth_{index}.npy",
                                                      intrinsics[0], mask_path=mask_path)


# ---------------------------------------------------------------------------
# Low-level readers
# ---------------------------------------------------------------------------


def _require_file(path: Path) -> None:
    if not path.is_file():
        raise InputError(f"{path}: file not found")


def _read_image(path, flags) -> np.ndarray:
    path = Path(path)
    _require_file(path)
    _check_image_size(path)
    try:
        data = np.frombuffer(path.read_bytes(), dtype=np.uint8)
    except OSError as err:
        raise InputError(f"{path}: cannot read file ({err.strerror or err})") from None
    with _quiet_stderr():
        try:
            image = cv2.imdecode(data, flags) if data.size else None
        except cv2.error:
            image = None
    if image is None:
        raise InputError(f"{path}: not a readable image (PNG, JPG, TIFF, ...)")
    return image


@contextmanager
def _quiet_stderr():
    """File descriptor 2 sent to /dev/null: OpenCV's decoders (libpng) print their errors from C."""
    saved = os.dup(2)
    try:
        with open(os.devnull, "wb") as null:
            os.dup2(null.fileno(), 2)
        yield
    finally:
        os.dup2(saved, 2)
        os.close(saved)


def _check_image_size(path: Path) -> None:
    """Refuse an image of more than ``MAX_IMAGE_PIXELS`` from its header, before it is decoded; one Pillow cannot
    read is left to OpenCV, which refuses what it cannot decode."""
    from PIL import Image  # matplotlib's dependency: reads the header only

    try:
        with Image.open(path) as image:
            width, height = image.size
    except Exception:  # noqa: BLE001 -- any reason Pillow cannot read a header: OpenCV decides
        return
    _check_pixels(path, width, height)


def _check_pixels(path: Path, width: int, height: int) -> None:
    if width * height > tol.MAX_IMAGE_PIXELS:
        raise InputError(f"{path}: a {width}x{height} image has more than {tol.MAX_IMAGE_PIXELS:,} pixels, "
                         f"the most contourgrasp reads")


def _load_npy(path: Path) -> np.ndarray:
    _require_file(path)
    try:
        header = np.load(path, mmap_mode="r", allow_pickle=False)  # the shape, before the data is read
    except (OSError, ValueError, EOFError) as err:
        raise InputError(f"{path}: not a readable .npy array ({err})") from None
    shape = getattr(header, "shape", ())
    if len(shape) >= 2:
        _check_pixels(path, shape[1], shape[0])
    elif math.prod(shape) > tol.MAX_IMAGE_PIXELS:
        raise InputError(f"{path}: an array of {math.prod(shape):,} values, more than an image contourgrasp reads")
    try:
        data = np.load(path, allow_pickle=False)
    except (OSError, ValueError, EOFError) as err:
        raise InputError(f"{path}: not a readable .npy array ({err})") from None
    if not isinstance(data, np.ndarray) or data.dtype.kind not in "biuf":
        raise InputError(f"{path}: expected an array of real numbers, got dtype {getattr(data, 'dtype', None)}")
    return data


def _read_text(path: Path) -> str:
    _require_file(path)
    try:
        return path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise InputError(f"{path}: cannot read file ({err})") from None


def _read_mapping(path: Path):
    """A JSON or YAML file's data. YAML aliases are refused (camera data needs none, and a few of them make a
    file of bytes into an array of gigabytes); so are numbers of more digits than Python reads."""
    text = _read_text(path)
    try:
        if path.suffix.lower() in (".yaml", ".yml"):
            return _read_yaml(path, text)
        return json.loads(text)
    except InputError:
        raise
    except json.JSONDecodeError as err:
        raise InputError(f"{path}: not valid JSON ({err})") from None
    except RecursionError:
        raise InputError(f"{path}: nested too deeply to be camera data") from None
    except ValueError as err:  # an integer of more than sys.get_int_max_str_digits() digits
        raise InputError(f"{path}: a number too long to be camera data ({str(err).split(';')[0]})") from None


def _read_yaml(path: Path, text: str):
    import yaml

    class NoAliases(yaml.SafeLoader):
        def compose_node(self, parent, index):
            if self.check_event(yaml.AliasEvent):
                raise InputError(f"{path}: YAML aliases (*name) are not camera data; write the values out")
            return super().compose_node(parent, index)

    try:
        return yaml.load(text, Loader=NoAliases)  # noqa: S506 -- a SafeLoader
    except yaml.YAMLError as err:
        raise InputError(f"{path}: not valid YAML ({' '.join(str(err).split())})") from None


def _field(path, data: dict, key: str, name: str | None = None):
    if key not in data:
        raise InputError(f"{path}: missing field {name or key}")
    return data[key]


def _numbers(path, values, name, shape) -> np.ndarray:
    try:
        array = np.array(values, dtype=float)
    except (TypeError, ValueError):
        raise InputError(f"{path}: field {name} must hold numbers") from None
    if array.shape != shape:
        raise InputError(f"{path}: field {name} must have shape {shape}, got {array.shape}")
    if not np.all(np.isfinite(array)):
        raise InputError(f"{path}: field {name} holds a NaN or infinite value")
    return array
