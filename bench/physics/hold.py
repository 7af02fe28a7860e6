#!/usr/bin/env python3
"""MuJoCo grasp-hold benchmark for Tsukami's returned grasps (issue #22 item 6).

Reads cases (JSON Lines written by `plugins/grasp-planner/examples/physics_cases.rs`),
builds for each the hand subtree of the robot's URDF welded at the reply's palm
pose and the object as a free body, squeezes, then pulls the object with its weight
in six directions; a grasp HOLDS when the object stays within 2 cm and 15 deg of
its planned pose in all six. Runs the controls first and exits non-zero when one
misbehaves. Protocol, constants and output: README.md beside this file.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import math
import os
import sys
import time
import tomllib
from collections import defaultdict

import mujoco
import numpy as np
import trimesh

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from urdf_mjcf import fmt, hand_from_urdf, mat_to_quat  # noqa: E402

REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))
CACHE = os.path.join(REPO, "target", "physics-cache")

# ---- The protocol's constants (README.md says why) ---------------------------------
G = 9.81                      # m/s^2, the pull's magnitude is m*G
TIMESTEP = 0.001              # s
SETTLE_S = 0.3                # s of squeezing with no external force
PULL_S = 1.0                  # s of pulling per direction
MAX_SHIFT = 0.02              # m, of the centre of mass from its planned place
MAX_TURN = math.radians(15)   # rad, of the object from its planned orientation
SERVO_SPAN = 0.2              # rad: kp = effort / SERVO_SPAN without a squeeze entry
FALLBACK_SQUEEZE = 0.1        # rad beyond the planned position on the flex joints
RAMP_S = 0.0                  # s: targets stepped at t = 0 (--ramp S: a linear ramp, diagnosis only)
DAMPRATIO = 1.0               # servo damping: critical (MuJoCo's dampratio)
ARMATURE = 1e-4               # kg m^2 (or kg) on every hand joint: the motor's reflected inertia
SOLREF = (0.01, 1.0)          # the "rubber pad": 10 ms time constant, critically damped
SOLIMP = (0.9, 0.95, 0.001, 0.5, 2.0)
IMPRATIO = 10.0               # elliptic cones, friction 10x harder than normal (less creep)
NOISE_SHIFT = 0.003           # m, pose-noise variant: up to 3 mm
NOISE_TURN = math.radians(3)  # rad, and up to 3 deg
NOISE_SEED = 22
OPEN_BY = 0.3                 # rad, control (a)
DIRECTIONS = {
    "-z": (0, 0, -1), "+z": (0, 0, 1), "+x": (1, 0, 0),
    "-x": (-1, 0, 0), "+y": (0, 1, 0), "-y": (0, -1, 0),
}
COACD_THRESHOLD = 0.05
CONVEX_RATIO = 0.97           # volume / hull volume above which a closed mesh counts convex


def quat_xyzw_to_wxyz(q):
    return np.array([q[3], q[0], q[1], q[2]], dtype=float)


def quat_to_mat(q_wxyz):
    m = np.zeros(9)
    mujoco.mju_quat2Mat(m, np.asarray(q_wxyz, dtype=float))
    return m.reshape(3, 3)


def rot_angle(r):
    return math.acos(max(-1.0, min(1.0, (np.trace(r) - 1) / 2)))


# ---- Object: mass properties and convex decomposition ------------------------------

def file_hash(path, extra=""):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        h.update(f.read())
    h.update(extra.encode())
    return h.hexdigest()[:20]


def load_mesh(path, scale):
    m = trimesh.load(path, force="mesh", process=True)
    m.apply_scale(scale)
    if m.is_watertight and m.volume < 0:
        m.invert()
    return m


def mass_properties(mesh, mass, com=None):
    """Centre of mass (mesh frame) and inertia about it, for a uniform solid of `mass`.
    A mesh that does not close a volume is replaced by its convex hull here."""
    solid = mesh if (mesh.is_watertight and mesh.volume > 1e-9) else mesh.convex_hull
    c0 = np.array(solid.center_mass)
    inertia = np.array(solid.moment_inertia) * (mass / solid.mass)
    c = c0 if com is None else np.array(com, dtype=float)
    d = c - c0
    inertia = inertia + mass * (np.dot(d, d) * np.eye(3) - np.outer(d, d))
    return c, inertia, solid is mesh


def convex_parts(path, scale):
    """Convex pieces (files) of the mesh: the mesh itself when convex, else CoACD's,
    cached under target/physics-cache/ by the file's hash."""
    key = file_hash(path, f"{scale}|{COACD_THRESHOLD}")
    d = os.path.join(CACHE, key)
    index = os.path.join(d, "parts.json")
    if os.path.exists(index):
        with open(index) as f:
            return json.load(f)
    os.makedirs(d, exist_ok=True)
    mesh = load_mesh(path, scale)
    hull = mesh.convex_hull
    convex = mesh.is_watertight and mesh.volume / max(hull.volume, 1e-12) > CONVEX_RATIO
    parts = []
    if convex:
        pieces = [(hull.vertices, hull.faces)]
        how = "convex"
    else:
        import coacd
        coacd.set_log_level("error")
        pieces = coacd.run_coacd(coacd.Mesh(mesh.vertices, mesh.faces), threshold=COACD_THRESHOLD, seed=0)
        how = "coacd"
    for k, (v, f) in enumerate(pieces):
        p = trimesh.Trimesh(v, f, process=True)
        if p.convex_hull.volume < 1e-10:
            continue
        fn = os.path.join(d, f"part{k:03d}.stl")
        p.export(fn)
        parts.append(fn)
    info = {"how": how, "parts": parts}
    with open(index, "w") as f:
        json.dump(info, f)
    return info


# ---- Hands ---------------------------------------------------------------------------

class HandSpec:
    """The hand to simulate: the MJCF fragment, its movable joints, and per joint the
    start position, servo target and stiffness."""

    def __init__(self, body_xml, meshes, joints, q0, target, kp, flex=(), fingers=None):
        self.body_xml = body_xml
        self.meshes = meshes
        self.joints = joints          # name -> urdf_mjcf.Joint
        self.q0 = q0                  # name -> start
        self.target = target          # actuated name -> servo target
        self.kp = kp                  # actuated name -> stiffness
        self.flex = list(flex)
        self.fingers = fingers or []


def load_description(path, hand_name):
    with open(path, "rb") as f:
        d = tomllib.load(f)
    for h in d.get("hand", []):
        if h.get("name") == hand_name:
            return d, h
    raise ValueError(f"{path}: no hand {hand_name}")


_hand_cache = {}


def urdf_hand(robot):
    key = (robot["urdf"], robot["description"], robot.get("hand", "right"))
    if key not in _hand_cache:
        _, h = load_description(robot["description"], robot.get("hand", "right"))
        hand = hand_from_urdf(robot["urdf"], h["palm_link"])
        _hand_cache[key] = (hand, h)
    return _hand_cache[key]


def hand_for_reply(robot, reply, mode="nominal"):
    """The servo set-up of a returned grasp (mode "nominal"), or of control (a)
    "open" (flex joints opened by OPEN_BY, targets there), or control (b) "two"
    (all fingers but index and middle opened fully, those keep their squeeze)."""
    hand, desc = urdf_hand(robot)
    jp = reply["joint_positions"]
    fingers = desc.get("fingers", [])
    flex = [j for f in fingers for j in f.get("flex", [])]
    q0 = {}
    for name, j in hand.joints.items():
        if name in jp:
            q0[name] = float(jp[name])
    for name, j in hand.joints.items():
        if name not in q0:
            if j.mimic and j.mimic[0] in q0:
                q0[name] = j.mimic[1] * q0[j.mimic[0]] + j.mimic[2]
            else:
                q0[name] = float(np.clip(0.0, j.lower, j.upper))
    squeeze = {s["joint"]: s for s in (reply.get("squeeze") or [])}
    target, kp = {}, {}
    for j in hand.actuated():
        s = squeeze.get(j.name)
        kp[j.name] = float(s["stiffness"]) if s and s.get("stiffness") else j.effort / SERVO_SPAN
        if s is not None:
            target[j.name] = float(s["target"])
        elif not squeeze and j.name in flex:
            target[j.name] = min(q0[j.name] + FALLBACK_SQUEEZE, j.upper)
        else:
            target[j.name] = q0[j.name]
    if mode == "open":
        for name in flex:
            j = hand.joints[name]
            q0[name] = max(q0[name] - OPEN_BY, j.lower)
            target[name] = q0[name]
    elif mode == "two":
        for f in fingers:
            if f["name"] in ("index", "middle"):
                continue
            for name in f.get("flex", []):
                q0[name] = hand.joints[name].lower
                target[name] = q0[name]
    for name, j in hand.joints.items():  # followers start where their leader puts them
        if j.mimic:
            q0[name] = j.mimic[1] * q0[j.mimic[0]] + j.mimic[2]
    return HandSpec(hand.body_xml, hand.meshes, hand.joints, q0, target, kp, flex, fingers)


# ---- Model -------------------------------------------------------------------------------

def build_xml(hand, palm_pos, palm_quat, parts, obj_pos, obj_quat, mass, com, inertia, mu):
    w, v = np.linalg.eigh(inertia)
    if np.linalg.det(v) < 0:
        v[:, 0] = -v[:, 0]
    w = np.maximum(w, 1e-9)
    assets = [f'<mesh name="{n}" file="{f}" scale="{fmt(s)}"/>' for n, f, s in hand.meshes]
    assets += [f'<mesh name="obj{k}" file="{p}"/>' for k, p in enumerate(parts)]
    obj_geoms = "\n".join(
        f'      <geom type="mesh" mesh="obj{k}" class="object"/>' for k in range(len(parts))
    )
    acts, eqs = [], []
    for j in hand.joints.values():
        if j.mimic:
            leader, mult, off = j.mimic
            eqs.append(f'<joint joint1="{j.name}" joint2="{leader}" polycoef="{off:.9g} {mult:.9g} 0 0 0"/>')
        else:
            acts.append(
                f'<position name="a_{j.name}" joint="{j.name}" kp="{hand.kp[j.name]:.9g}" '
                f'dampratio="{DAMPRATIO}" forcelimited="true" '
                f'forcerange="{-j.effort:.9g} {j.effort:.9g}"/>'
            )
    body = hand.body_xml.replace("{PALM_POS}", fmt(palm_pos)).replace("{PALM_QUAT}", fmt(palm_quat))
    contact = f'condim="3" friction="{mu:.9g} 0 0" solref="{fmt(SOLREF)}" solimp="{fmt(SOLIMP)}"'
    return f"""<mujoco model="hold">
  <compiler angle="radian" inertiafromgeom="false" autolimits="true"/>
  <option timestep="{TIMESTEP}" gravity="0 0 0" integrator="implicitfast" cone="elliptic" impratio="{IMPRATIO}"/>
  <default>
    <default class="hand">
      <geom contype="1" conaffinity="0" {contact}/>
      <joint armature="{ARMATURE}" damping="0"/>
    </default>
    <default class="object">
      <geom contype="0" conaffinity="1" {contact}/>
    </default>
  </default>
  <asset>
    {chr(10).join('    ' + a for a in assets).strip()}
  </asset>
  <worldbody>
{body}
    <body name="object" pos="{fmt(obj_pos)}" quat="{fmt(obj_quat)}">
      <freejoint name="object_free"/>
      <inertial pos="{fmt(com)}" quat="{fmt(mat_to_quat(v))}" mass="{mass:.9g}" diaginertia="{fmt(w)}"/>
{obj_geoms}
    </body>
  </worldbody>
  <actuator>
    {chr(10).join('    ' + a for a in acts).strip()}
  </actuator>
  <equality>
    {chr(10).join('    ' + e for e in eqs).strip()}
  </equality>
</mujoco>
"""


def noise_pose(name, pos, quat_wxyz, com):
    """Deterministic pose error (seeded by the case name): the object turned about its
    centre of mass by up to NOISE_TURN and shifted by up to NOISE_SHIFT."""
    seed = int.from_bytes(hashlib.sha256(f"{NOISE_SEED}:{name}".encode()).digest()[:8], "little")
    rng = np.random.default_rng(seed)
    def unit():
        v = rng.normal(size=3)
        return v / np.linalg.norm(v)
    shift = unit() * rng.uniform(0, NOISE_SHIFT)
    axis, angle = unit(), rng.uniform(0, NOISE_TURN)
    dq = np.zeros(4)
    mujoco.mju_axisAngle2Quat(dq, axis, angle)
    r = quat_to_mat(quat_wxyz)
    c_world = pos + r @ com
    q = np.zeros(4)
    mujoco.mju_mulQuat(q, dq, quat_wxyz)
    r2 = quat_to_mat(q)
    pos2 = c_world + shift - r2 @ com
    return pos2, q, float(np.linalg.norm(shift)), math.degrees(angle)


# ---- Simulation ----------------------------------------------------------------------------

def deviation(d, obj, c_ref, r_ref):
    shift = float(np.linalg.norm(d.xipos[obj] - c_ref))
    turn = rot_angle(r_ref.T @ d.xmat[obj].reshape(3, 3))
    return shift, turn


def contact_summary(m, d, obj):
    links = set()
    deepest = 0.0
    for k in range(d.ncon):
        c = d.contact[k]
        b1, b2 = m.geom_bodyid[c.geom1], m.geom_bodyid[c.geom2]
        if obj in (b1, b2):
            other = b2 if b1 == obj else b1
            links.add(m.body(other).name)
            deepest = min(deepest, c.dist)
    return sorted(links), deepest


def planned_gaps(m, d, obj, planned_links):
    """Distance (mm) from each planned contact link to the object at the start: checks
    that the converted hand is where the planner put it."""
    og = [g for g in range(m.ngeom) if m.geom_bodyid[g] == obj]
    out = {}
    for link in planned_links:
        try:
            b = m.body(link).id
        except KeyError:
            continue
        best = math.inf
        for g in range(m.ngeom):
            if m.geom_bodyid[g] != b:
                continue
            for g2 in og:
                best = min(best, mujoco.mj_geomDistance(m, d, g, g2, 0.05, None))
        out[link] = round(1e3 * best, 2)
    return out


def run_sim(xml, hand, mass, c_ref, r_ref, palm_rot=np.eye(3), planned_links=()):
    m = mujoco.MjModel.from_xml_string(xml)
    d = mujoco.MjData(m)
    for name, q in hand.q0.items():
        d.qpos[m.jnt_qposadr[m.joint(name).id]] = q
    act = [(m.actuator(f"a_{name}").id, hand.q0[name], t) for name, t in hand.target.items()]
    def ramp(time_s):
        a = 1.0 if RAMP_S <= 0 else min(1.0, time_s / RAMP_S)
        for i, q, t in act:
            d.ctrl[i] = q + a * (t - q)
    ramp(0.0)
    obj = m.body("object").id
    mujoco.mj_forward(m, d)
    start_links, start_depth = contact_summary(m, d, obj)
    res = {"planned_contact_gap_mm": planned_gaps(m, d, obj, planned_links),
           "start_contacts": start_links, "start_penetration_mm": round(-1e3 * start_depth, 2)}
    worst_s, worst_t = 0.0, 0.0
    first_touch, most = None, (0, [])
    for k in range(int(round(SETTLE_S / TIMESTEP))):
        ramp(k * TIMESTEP)
        mujoco.mj_step(m, d)
        s, t = deviation(d, obj, c_ref, r_ref)
        worst_s, worst_t = max(worst_s, s), max(worst_t, t)
        links, _ = contact_summary(m, d, obj)
        if links and first_touch is None:
            first_touch = (k + 1) * TIMESTEP
        if len(links) > most[0]:
            most = (len(links), links)
    links, depth = contact_summary(m, d, obj)
    s, t = deviation(d, obj, c_ref, r_ref)
    shift_palm = palm_rot.T @ (d.xipos[obj] - c_ref)
    res["settle"] = {"shift_mm": round(1e3 * s, 2), "turn_deg": round(math.degrees(t), 2),
                     "max_shift_mm": round(1e3 * worst_s, 2), "max_turn_deg": round(math.degrees(worst_t), 2),
                     "shift_in_palm_frame_mm": [round(1e3 * float(x), 1) for x in shift_palm],
                     "first_touch_s": first_touch, "most_contacts": most[1],
                     "contacts": links, "penetration_mm": round(-1e3 * depth, 2)}
    settled_ok = worst_s <= MAX_SHIFT and worst_t <= MAX_TURN
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    state = np.zeros(mujoco.mj_stateSize(m, spec))
    mujoco.mj_getState(m, d, state, spec)
    res["pull"] = {}
    holds = settled_ok
    for dname, dvec in DIRECTIONS.items():
        mujoco.mj_setState(m, d, state, spec)
        mujoco.mj_forward(m, d)
        d.xfrc_applied[obj, :3] = mass * G * np.array(dvec, dtype=float)
        ws, wt, fail_at = worst_s, worst_t, None
        n = int(round(PULL_S / TIMESTEP))
        for k in range(n):
            mujoco.mj_step(m, d)
            s, t = deviation(d, obj, c_ref, r_ref)
            ws, wt = max(ws, s), max(wt, t)
            if fail_at is None and (s > MAX_SHIFT or t > MAX_TURN):
                fail_at = (k + 1) * TIMESTEP
                break  # it has let go; the rest of the second changes nothing
        s, t = deviation(d, obj, c_ref, r_ref)
        ok = fail_at is None and settled_ok
        holds = holds and ok
        res["pull"][dname] = {"holds": ok, "shift_mm": round(1e3 * s, 2), "turn_deg": round(math.degrees(t), 2),
                              "max_shift_mm": round(1e3 * ws, 2), "max_turn_deg": round(math.degrees(wt), 2),
                              "fails_at_s": fail_at}
        d.xfrc_applied[obj, :] = 0
    res["holds"] = holds
    return res


def object_setup(obj_case):
    mesh_path = obj_case["mesh"]
    scale = float(obj_case.get("scale") or 1.0)
    mesh = load_mesh(mesh_path, scale)
    com, inertia, closed = mass_properties(mesh, float(obj_case["mass"]), obj_case.get("center_of_mass"))
    info = convex_parts(mesh_path, scale)
    return com, inertia, closed, info


def judge(case, hand, noise=False):
    """Runs one case with the given hand set-up; returns the result record."""
    o = case["object"]
    reply = case["reply"]
    com, inertia, closed, info = object_setup(o)
    mass = float(o["mass"])
    mu = float(reply.get("mu", o.get("friction", 0.5)))
    pos = np.array(o["pose"]["position"], dtype=float)
    quat = quat_xyzw_to_wxyz(o["pose"]["quaternion"])
    r_plan = quat_to_mat(quat)
    planner_com = reply.get("object", {}).get("center_of_mass")
    com_source = "case" if o.get("center_of_mass") is not None else "mesh"
    if not closed and o.get("center_of_mass") is None and planner_com is not None:
        # The mesh closes no volume trimesh can measure (e.g. a handle touching the body
        # along an edge): take the planner's centroid of the enclosed volume instead of the hull's.
        c = r_plan.T @ (np.array(planner_com, dtype=float) - pos)
        mesh = load_mesh(o["mesh"], float(o.get("scale") or 1.0))
        com, inertia, _ = mass_properties(mesh, mass, c)
        com_source = "planner"
    c_plan = pos + r_plan @ com
    noise_info = None
    if noise:
        pos, quat, dn, an = noise_pose(case["case"], pos, quat, com)
        noise_info = {"shift_mm": round(1e3 * dn, 2), "turn_deg": round(an, 2)}
    pp = reply["palm_pose"]
    xml = build_xml(hand, np.array(pp["position"], dtype=float), quat_xyzw_to_wxyz(pp["quaternion"]),
                    info["parts"], pos, quat, mass, com, inertia, mu)
    t = time.perf_counter()
    palm_rot = quat_to_mat(quat_xyzw_to_wxyz(pp["quaternion"]))
    res = run_sim(xml, hand, mass, c_plan, r_plan, palm_rot, [c["link"] for c in reply.get("contacts", [])])
    res["sim_s"] = round(time.perf_counter() - t, 3)
    res["object"] = {"decomposition": info["how"], "parts": len(info["parts"]), "closed": closed,
                     "mass": mass, "mu": mu}
    if noise_info:
        res["noise"] = noise_info
    res["object"]["com_source"] = com_source
    if planner_com is not None:
        res["com_vs_planner_mm"] = round(1e3 * float(np.linalg.norm(np.array(planner_com) - c_plan)), 2)
    return res


# ---- Synthetic controls ----------------------------------------------------------------------

CYL_R, CYL_H, CYL_MASS, CYL_MU = 0.033, 0.12, 0.35, 0.5
PAD_HALF = (0.004, 0.012, 0.012)  # radial, tangential, axial half sizes (m)
PAD_EFFORT = 10.0                 # N per pad
PAD_SPAN = 0.01                   # m: kp = PAD_EFFORT / PAD_SPAN
PAD_PRESS = 0.004                 # m: servo target beyond contact


def cylinder_mesh():
    os.makedirs(CACHE, exist_ok=True)
    path = os.path.join(CACHE, f"control_cylinder_{CYL_R}_{CYL_H}.stl")
    if not os.path.exists(path):
        trimesh.creation.cylinder(radius=CYL_R, height=CYL_H, sections=64).export(path)
    return path


def pad_hand(azimuths, heights):
    """A synthetic gripper: flat pads (boxes) on radial slides around a vertical
    cylinder at the origin, each on a position servo pressing PAD_PRESS beyond contact."""
    from urdf_mjcf import Joint
    lines = ['    <body name="pad_base" pos="{PALM_POS}" quat="{PALM_QUAT}">',
             '      <geom type="sphere" size="0.001" class="hand" contype="0"/>']
    joints, q0, target, kp = {}, {}, {}, {}
    k = 0
    for az in azimuths:
        for z in heights:
            c, s = math.cos(az), math.sin(az)
            r = CYL_R + PAD_HALF[0]
            name = f"pad{k}"
            # Body frame: x along the inward radial direction.
            rot = np.array([[-c, s, 0], [-s, -c, 0], [0, 0, 1]])
            lines.append(f'      <body name="{name}" pos="{fmt([r * c, r * s, z])}" quat="{fmt(mat_to_quat(rot))}">')
            lines.append(f'        <joint name="{name}" type="slide" axis="1 0 0" range="-0.02 0.02" class="hand"/>')
            lines.append('        <inertial pos="0 0 0" mass="0.02" diaginertia="1e-6 1e-6 1e-6"/>')
            lines.append(f'        <geom type="box" size="{fmt(PAD_HALF)}" class="hand"/>')
            lines.append('      </body>')
            joints[name] = Joint(name, "slide", -0.02, 0.02, PAD_EFFORT)
            q0[name] = 0.0
            target[name] = PAD_PRESS
            kp[name] = PAD_EFFORT / PAD_SPAN
            k += 1
    lines.append("    </body>")
    return HandSpec("\n".join(lines), [], joints, q0, target, kp)


def synthetic_case(name):
    return {"case": name, "family": "control", "placement": "synthetic",
            "object": {"mesh": cylinder_mesh(), "scale": 1.0,
                       "pose": {"position": [0, 0, 0], "quaternion": [0, 0, 0, 1]},
                       "mass": CYL_MASS, "center_of_mass": None, "friction": CYL_MU},
            "reply": {"mu": CYL_MU, "palm_pose": {"position": [0, 0, 0], "quaternion": [0, 0, 0, 1]},
                      "joint_positions": {}, "grasp_type": {"name": "control"}}}


def run_controls(cases, log):
    """The harness's own checks; returns (records, ok)."""
    records, ok = [], True
    quarter = [k * math.pi / 2 for k in range(4)]
    checks = [
        ("c: synthetic 8-pad wrap of a cylinder", True, synthetic_case("control/wrap8"),
         pad_hand(quarter, (-0.03, 0.03))),
        ("b: synthetic two pads on one side", False, synthetic_case("control/two_pads"),
         pad_hand([0.0], (-0.03, 0.03))),
    ]
    real = [c for c in cases if c.get("robot")]
    if real:
        c = real[0]
        checks.append((f"a: {c['case']} opened {OPEN_BY} rad, no squeeze", False, c,
                       hand_for_reply(c["robot"], c["reply"], "open")))
    tips = [c for c in real if "fingertip" in c["reply"]["grasp_type"].get("style", "")
            or c["reply"]["grasp_type"]["name"].startswith("fingertip")]
    if tips:
        c = tips[0]
        checks.append((f"b: {c['case']} with only index and middle squeezing", False, c,
                       hand_for_reply(c["robot"], c["reply"], "two")))
    for label, must_hold, case, hand in checks:
        res = judge(case, hand)
        good = res["holds"] == must_hold
        ok = ok and good
        worst = max(res["pull"].items(), key=lambda kv: kv[1]["max_shift_mm"])
        log(f"  control {label}: {'HOLDS' if res['holds'] else 'fails'} "
            f"(must {'hold' if must_hold else 'fail'}) -> {'ok' if good else 'MISBEHAVES'}; "
            f"settle shift {res['settle']['shift_mm']} mm, worst pull {worst[0]} "
            f"{worst[1]['max_shift_mm']} mm / {worst[1]['max_turn_deg']} deg")
        records.append({"control": label, "must_hold": must_hold, "ok": good, "result": res})
    return records, ok


# ---- Reporting ---------------------------------------------------------------------------------

def rates(records, key):
    groups = defaultdict(lambda: [0, 0, 0])
    for r in records:
        g = groups[key(r)]
        g[0] += 1
        g[1] += r["nominal"]["holds"]
        if "noise" in r:
            g[2] += r["noise"]["holds"]
    return dict(sorted(groups.items()))


def pct(a, n):
    return f"{100.0 * a / n:.0f} %" if n else "-"


def summary(records, noise):
    out = {}
    for title, key in (("overall", lambda r: "all"), ("robot", lambda r: r["robot"]),
                       ("grasp_type", lambda r: r["grasp_type"]), ("family", lambda r: r["family"])):
        out[title] = {k: {"cases": v[0], "holds": v[1], **({"holds_noise": v[2]} if noise else {})}
                      for k, v in rates(records, key).items()}
    fails = defaultdict(int)
    for r in records:
        for dn, p in r["nominal"]["pull"].items():
            if not p["holds"]:
                fails[dn] += 1
    out["failing_direction_counts"] = dict(fails)
    out["failure_modes"] = failure_modes(records)
    return out


def failure_modes(records):
    """Per grasp type: how the nominal failures fail. `lost_in_squeeze`: the object left
    the 2 cm / 15 deg bound while the servos squeezed with no load (pushed out of the
    hand); `lost_under_load`: it stayed during the squeeze but some pull moved it out.
    `median_out_of_palm_mm`: the median settle shift along the palm normal (+ = away
    from the palm); `contacts_kept`: hand links touching after the squeeze / planned."""
    by = defaultdict(list)
    for r in records:
        by[r["grasp_type"]].append(r)
    out = {}
    for gt, rs in sorted(by.items()):
        fails = [r for r in rs if not r["nominal"]["holds"]]
        squeeze = [r for r in fails if r["nominal"]["settle"]["max_shift_mm"] > 1e3 * MAX_SHIFT
                   or r["nominal"]["settle"]["max_turn_deg"] > math.degrees(MAX_TURN)]
        load = [r for r in fails if r not in squeeze]
        dirs = defaultdict(int)
        for r in load:
            for dn, p in r["nominal"]["pull"].items():
                if not p["holds"]:
                    dirs[dn] += 1
        kept = [len(r["nominal"]["settle"]["contacts"]) for r in rs]
        out_palm = sorted(r["nominal"]["settle"]["shift_in_palm_frame_mm"][2] for r in rs)
        turns = sorted(r["nominal"]["settle"]["turn_deg"] for r in rs)
        out[gt] = {"cases": len(rs), "holds": len(rs) - len(fails), "lost_in_squeeze": len(squeeze),
                   "lost_under_load": len(load), "load_failure_directions": dict(dirs),
                   "mean_contacts_kept": round(float(np.mean(kept)), 2),
                   "median_out_of_palm_mm": out_palm[len(out_palm) // 2],
                   "median_settle_turn_deg": turns[len(turns) // 2]}
    return out


def markdown(summ, noise, controls):
    lines = []
    head = "| group | cases | holds | hold rate |" + (" holds (noise) | hold rate (noise) |" if noise else "")
    sep = "|---|---:|---:|---:|" + ("---:|---:|" if noise else "")
    for title in ("overall", "robot", "grasp_type", "family"):
        lines += [f"\n**By {title.replace('_', ' ')}**\n", head, sep]
        for k, v in summ[title].items():
            row = f"| {k} | {v['cases']} | {v['holds']} | {pct(v['holds'], v['cases'])} |"
            if noise:
                row += f" {v['holds_noise']} | {pct(v['holds_noise'], v['cases'])} |"
            lines.append(row)
    lines += ["\n**Failure modes (nominal)**\n",
              "| grasp type | cases | holds | lost in squeeze | lost under load | load-failure directions | contacts kept | median out-of-palm shift (mm) |",
              "|---|---:|---:|---:|---:|---|---:|---:|"]
    for gt, v in summ["failure_modes"].items():
        dirs = ", ".join(f"{k} {n}" for k, n in sorted(v["load_failure_directions"].items())) or "-"
        lines.append(f"| {gt} | {v['cases']} | {v['holds']} | {v['lost_in_squeeze']} | {v['lost_under_load']} | "
                     f"{dirs} | {v['mean_contacts_kept']} | {v['median_out_of_palm_mm']} |")
    lines += ["\n**Controls**\n", "| control | must | outcome |", "|---|---|---|"]
    for c in controls:
        lines.append(f"| {c['control']} | {'hold' if c['must_hold'] else 'fail'} | "
                     f"{'holds' if c['result']['holds'] else 'fails'} ({'ok' if c['ok'] else 'MISBEHAVES'}) |")
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--cases", action="append", default=[], help="JSON Lines of cases (repeatable)")
    ap.add_argument("--noise", action="store_true", help="also run the pose-noise variant")
    ap.add_argument("--only", default="", help="only cases whose name contains TEXT")
    ap.add_argument("--limit", type=int, default=0, help="at most N cases")
    ap.add_argument("--json", help="write the results here")
    ap.add_argument("--md", help="write the Markdown tables here")
    ap.add_argument("--controls-only", action="store_true")
    ap.add_argument("--quiet", action="store_true", help="no line per case")
    ap.add_argument("--fallback-squeeze", type=float, default=None,
                    help="diagnosis only, not the protocol: rad beyond planned for the fallback")
    ap.add_argument("--summarize", metavar="RESULTS.json",
                    help="no simulation: recompute the summary and --md from a results file")
    ap.add_argument("--ramp", type=float, default=None, help="diagnosis only: RAMP_S in s (0: step)")
    a = ap.parse_args()
    if a.ramp is not None:
        global RAMP_S
        RAMP_S = a.ramp
    if a.summarize:
        with open(a.summarize) as f:
            res = json.load(f)
        noise = any("noise" in r for r in res["cases"])
        summ = summary(res["cases"], noise)
        print(json.dumps(summ, indent=1))
        if a.md:
            with open(a.md, "w") as f:
                f.write(markdown(summ, noise, res["controls"]))
        return 0 if all(c["ok"] for c in res["controls"]) else 1
    if a.fallback_squeeze is not None:
        global FALLBACK_SQUEEZE
        FALLBACK_SQUEEZE = a.fallback_squeeze
    log = lambda s: print(s, flush=True)  # noqa: E731
    cases = []
    for fn in a.cases:
        with open(fn) as f:
            cases += [json.loads(l) for l in f if l.strip()]
    sel = [c for c in cases if a.only in c["case"]]
    if a.limit:
        sel = sel[: a.limit]
    t0 = time.perf_counter()
    log("controls:")
    controls, controls_ok = run_controls(sel or cases, log)
    records = []
    if not a.controls_only:
        log(f"{len(sel)} case(s){' with the pose-noise variant' if a.noise else ''}:")
    for c in ([] if a.controls_only else sel):
        robot = os.path.basename(c["robot"]["urdf"]).removesuffix(".urdf")
        rec = {"case": c["case"], "family": c["family"], "placement": c.get("placement"), "robot": robot,
               "grasp_type": c["reply"]["grasp_type"]["name"],
               "squeeze": "reply" if c["reply"].get("squeeze") else "fallback"}
        hand = hand_for_reply(c["robot"], c["reply"])
        rec["nominal"] = judge(c, hand)
        if a.noise:
            rec["noise"] = judge(c, hand, noise=True)
        records.append(rec)
        if not a.quiet:
            n = rec["nominal"]
            bad = [k for k, p in n["pull"].items() if not p["holds"]]
            extra = f" noise:{'HOLD' if rec['noise']['holds'] else 'fail'}" if a.noise else ""
            log(f"  {c['case']:<40} {rec['grasp_type']:<18} {'HOLD' if n['holds'] else 'fail'}{extra}"
                f"  settle {n['settle']['shift_mm']:.1f} mm {n['settle']['turn_deg']:.1f} deg"
                f" (palm xyz {n['settle']['shift_in_palm_frame_mm']}),"
                f" contacts {len(n['settle']['contacts'])}/{len(c['reply']['contacts'])}, fails {','.join(bad) or '-'}")
    summ = summary(records, a.noise)
    if records:
        log("hold rate:")
        for title in ("overall", "robot", "grasp_type", "family"):
            for k, v in summ[title].items():
                extra = f", noise {v['holds_noise']}/{v['cases']} ({pct(v['holds_noise'], v['cases'])})" if a.noise else ""
                log(f"  {title:<10} {k:<22} {v['holds']}/{v['cases']} ({pct(v['holds'], v['cases'])}){extra}")
        log(f"  failing directions (nominal): {summ['failing_direction_counts']}")
        log("failure modes (nominal):")
        for gt, v in summ["failure_modes"].items():
            log(f"  {gt:<18} {v}")
    log(f"controls {'ok' if controls_ok else 'MISBEHAVE'}; {time.perf_counter() - t0:.1f} s")
    constants = {k: v for k, v in globals().items() if k.isupper() and isinstance(v, (int, float, tuple, dict))}
    if a.json:
        os.makedirs(os.path.dirname(os.path.abspath(a.json)), exist_ok=True)
        with open(a.json, "w") as f:
            json.dump({"constants": constants, "mujoco": mujoco.__version__, "summary": summ,
                       "controls": controls, "cases": records}, f, indent=1, default=str)
    if a.md:
        os.makedirs(os.path.dirname(os.path.abspath(a.md)), exist_ok=True)
        with open(a.md, "w") as f:
            f.write(markdown(summ, a.noise, controls))
    return 0 if controls_ok else 1


if __name__ == "__main__":
    sys.exit(main())
