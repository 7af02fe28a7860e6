"""A small URDF -> MJCF converter for one hand: the subtree below a link.

What: `hand_from_urdf(urdf, palm_link, ...)` returns a `Hand`: the MJCF `<body>`
fragment of the subtree rooted at `palm_link` (the palm body has no joint: it
is welded to the world at the pose the caller gives), the movable joints with
their limits and efforts, and the URDF `<mimic>` couplings.

How: every URDF link becomes a body placed by its joint's origin; revolute and
continuous joints become hinges, prismatic joints slides (axis in the child
frame, as in URDF); fixed joints give a body without a joint. Collision
elements become geoms (box, cylinder, sphere, capsule -- the project's URDF
extension, `length` the cylindrical part --, mesh files resolved relative to
the URDF; `package://` meshes are skipped with a warning). Inertials are taken
from the URDF (diagonalised; a movable link without one gets a tiny one).
Visual elements are ignored. Nothing here is tuned per robot.
"""

from __future__ import annotations

import math
import os
import sys
import xml.etree.ElementTree as ET
from dataclasses import dataclass, field

import numpy as np


def rpy_to_mat(rpy):
    r, p, y = rpy
    cr, sr, cp, sp, cy, sy = math.cos(r), math.sin(r), math.cos(p), math.sin(p), math.cos(y), math.sin(y)
    rx = np.array([[1, 0, 0], [0, cr, -sr], [0, sr, cr]])
    ry = np.array([[cp, 0, sp], [0, 1, 0], [-sp, 0, cp]])
    rz = np.array([[cy, -sy, 0], [sy, cy, 0], [0, 0, 1]])
    return rz @ ry @ rx


def mat_to_quat(m):
    """Rotation matrix -> MuJoCo quaternion (w, x, y, z)."""
    m = np.asarray(m, dtype=float)
    t = np.trace(m)
    if t > 0:
        s = math.sqrt(t + 1.0) * 2
        q = [0.25 * s, (m[2, 1] - m[1, 2]) / s, (m[0, 2] - m[2, 0]) / s, (m[1, 0] - m[0, 1]) / s]
    elif m[0, 0] > m[1, 1] and m[0, 0] > m[2, 2]:
        s = math.sqrt(1.0 + m[0, 0] - m[1, 1] - m[2, 2]) * 2
        q = [(m[2, 1] - m[1, 2]) / s, 0.25 * s, (m[0, 1] + m[1, 0]) / s, (m[0, 2] + m[2, 0]) / s]
    elif m[1, 1] > m[2, 2]:
        s = math.sqrt(1.0 + m[1, 1] - m[0, 0] - m[2, 2]) * 2
        q = [(m[0, 2] - m[2, 0]) / s, (m[0, 1] + m[1, 0]) / s, 0.25 * s, (m[1, 2] + m[2, 1]) / s]
    else:
        s = math.sqrt(1.0 + m[2, 2] - m[0, 0] - m[1, 1]) * 2
        q = [(m[1, 0] - m[0, 1]) / s, (m[0, 2] + m[2, 0]) / s, (m[1, 2] + m[2, 1]) / s, 0.25 * s]
    q = np.array(q)
    return q / np.linalg.norm(q)


def fmt(v):
    return " ".join(f"{x:.9g}" for x in v)


def _origin(el):
    o = el.find("origin") if el is not None else None
    if o is None:
        return np.zeros(3), np.eye(3)
    xyz = [float(x) for x in o.get("xyz", "0 0 0").split()]
    rpy = [float(x) for x in o.get("rpy", "0 0 0").split()]
    return np.array(xyz), rpy_to_mat(rpy)


@dataclass
class Joint:
    name: str
    kind: str  # "hinge" or "slide"
    lower: float
    upper: float
    effort: float
    mimic: tuple | None = None  # (leader, multiplier, offset)


@dataclass
class Hand:
    body_xml: str  # the palm <body> and its subtree (pos/quat placeholders filled by the caller)
    joints: dict = field(default_factory=dict)  # name -> Joint, movable joints in tree order
    links: list = field(default_factory=list)
    meshes: list = field(default_factory=list)  # (asset name, file, scale)
    warnings: list = field(default_factory=list)

    def actuated(self):
        return [j for j in self.joints.values() if j.mimic is None]


# Tiny inertia for movable links the URDF gives none (kg, kg m^2).
TINY_MASS = 1e-3
TINY_INERTIA = 1e-8


def _inertial_xml(link):
    i = link.find("inertial")
    if i is None:
        return None
    mass = float(i.find("mass").get("value"))
    pos, rot = _origin(i)
    e = i.find("inertia")
    g = {k: float(e.get(k, "0")) for k in ("ixx", "iyy", "izz", "ixy", "ixz", "iyz")}
    tensor = np.array(
        [[g["ixx"], g["ixy"], g["ixz"]], [g["ixy"], g["iyy"], g["iyz"]], [g["ixz"], g["iyz"], g["izz"]]]
    )
    w, v = np.linalg.eigh(tensor)
    if np.linalg.det(v) < 0:
        v[:, 0] = -v[:, 0]
    # Valid principal moments: positive and satisfying the triangle inequality.
    w = np.maximum(w, TINY_INERTIA)
    for k in range(3):
        others = w.sum() - w[k]
        if w[k] > others:
            w[(k + 1) % 3] += (w[k] - others) / 2 + 1e-12
            w[(k + 2) % 3] += (w[k] - others) / 2 + 1e-12
    q = mat_to_quat(rot @ v)
    if mass <= 0:
        return None
    return f'<inertial pos="{fmt(pos)}" quat="{fmt(q)}" mass="{mass:.9g}" diaginertia="{fmt(w)}"/>'


def hand_from_urdf(urdf_path, palm_link, geom_class="hand", name_prefix=""):
    root = ET.parse(urdf_path).getroot()
    base = os.path.dirname(os.path.abspath(urdf_path))
    links = {l.get("name"): l for l in root.findall("link")}
    children = {}
    for j in root.findall("joint"):
        children.setdefault(j.find("parent").get("link"), []).append(j)
    if palm_link not in links:
        raise ValueError(f"{urdf_path}: no link {palm_link}")
    hand = Hand(body_xml="")

    def geoms(link):
        out = []
        for k, c in enumerate(link.findall("collision")):
            pos, rot = _origin(c)
            q = fmt(mat_to_quat(rot))
            g = c.find("geometry")
            shape = list(g)[0]
            tag = shape.tag
            attrs = f'class="{geom_class}" pos="{fmt(pos)}" quat="{q}"'
            if tag == "box":
                s = [float(x) / 2 for x in shape.get("size").split()]
                out.append(f'<geom type="box" size="{fmt(s)}" {attrs}/>')
            elif tag == "cylinder":
                out.append(
                    f'<geom type="cylinder" size="{float(shape.get("radius")):.9g} '
                    f'{float(shape.get("length")) / 2:.9g}" {attrs}/>'
                )
            elif tag == "capsule":
                r, l = float(shape.get("radius")), float(shape.get("length"))
                if l > 0:
                    out.append(f'<geom type="capsule" size="{r:.9g} {l / 2:.9g}" {attrs}/>')
                else:
                    out.append(f'<geom type="sphere" size="{r:.9g}" {attrs}/>')
            elif tag == "sphere":
                out.append(f'<geom type="sphere" size="{float(shape.get("radius")):.9g}" {attrs}/>')
            elif tag == "mesh":
                fn = shape.get("filename")
                if fn.startswith("package://"):
                    hand.warnings.append(f"{link.get('name')}: package mesh {fn} skipped")
                    continue
                if fn.startswith("file://"):
                    fn = fn[len("file://"):]
                path = fn if os.path.isabs(fn) else os.path.join(base, fn)
                scale = [float(x) for x in shape.get("scale", "1 1 1").split()]
                name = f"{name_prefix}{link.get('name')}_col{k}"
                hand.meshes.append((name, os.path.normpath(path), scale))
                out.append(f'<geom type="mesh" mesh="{name}" {attrs}/>')
            else:
                hand.warnings.append(f"{link.get('name')}: collision <{tag}> skipped")
        return out

    def body(link_name, joint_el, indent):
        link = links[link_name]
        hand.links.append(link_name)
        pad = "  " * indent
        lines = []
        if joint_el is None:
            lines.append(f'{pad}<body name="{name_prefix}{link_name}" pos="{{PALM_POS}}" quat="{{PALM_QUAT}}">')
        else:
            pos, rot = _origin(joint_el)
            lines.append(f'{pad}<body name="{name_prefix}{link_name}" pos="{fmt(pos)}" quat="{fmt(mat_to_quat(rot))}">')
        movable = False
        if joint_el is not None and joint_el.get("type") in ("revolute", "continuous", "prismatic"):
            movable = True
            jt = joint_el.get("type")
            kind = "slide" if jt == "prismatic" else "hinge"
            ax = joint_el.find("axis")
            axis = [float(x) for x in (ax.get("xyz") if ax is not None else "1 0 0").split()]
            lim = joint_el.find("limit")
            effort = float(lim.get("effort", "0")) if lim is not None else 0.0
            if jt == "continuous" or lim is None:
                lo, hi, rng = -math.inf, math.inf, 'limited="false"'
            else:
                lo, hi = float(lim.get("lower", "0")), float(lim.get("upper", "0"))
                rng = f'limited="true" range="{lo:.9g} {hi:.9g}"'
            mim = joint_el.find("mimic")
            mimic = None
            if mim is not None:
                mimic = (mim.get("joint"), float(mim.get("multiplier", "1")), float(mim.get("offset", "0")))
            name = joint_el.get("name")
            hand.joints[name] = Joint(name, kind, lo, hi, effort, mimic)
            lines.append(f'{pad}  <joint name="{name_prefix}{name}" type="{kind}" axis="{fmt(axis)}" {rng} class="{geom_class}"/>')
        elif joint_el is not None and joint_el.get("type") not in ("fixed",):
            hand.warnings.append(f"joint {joint_el.get('name')} of type {joint_el.get('type')} treated as fixed")
        inertial = _inertial_xml(link)
        if inertial is None and movable:
            inertial = f'<inertial pos="0 0 0" mass="{TINY_MASS}" diaginertia="{TINY_INERTIA} {TINY_INERTIA} {TINY_INERTIA}"/>'
            hand.warnings.append(f"{link_name}: no inertial, a tiny one used")
        if inertial is not None:
            lines.append(f"{pad}  {inertial}")
        for g in geoms(link):
            lines.append(f"{pad}  {g}")
        for j in children.get(link_name, []):
            lines.extend(body(j.find("child").get("link"), j, indent + 1))
        lines.append(f"{pad}</body>")
        return lines

    hand.body_xml = "\n".join(body(palm_link, None, 2))
    return hand


if __name__ == "__main__":
    h = hand_from_urdf(sys.argv[1], sys.argv[2])
    print(h.body_xml)
    for j in h.joints.values():
        print(j, file=sys.stderr)
    for w in h.warnings:
        print("warning:", w, file=sys.stderr)
