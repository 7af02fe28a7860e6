#!/usr/bin/env python3
"""Our trajectory timing against toppra's on the same paths and limits (issue #23).

Reads the export of `cargo run --release -p tsukami-trajectory-planner --example
timing_export -- FILE`: per paper scene and phase, the positions of the
trajectory's points (the path the controller follows) and the duration our
timing gave them, with each joint's velocity and acceleration limit. toppra
(H. Pham and Q.-C. Pham, T-RO 2018; `pip install toppra`) times a cubic spline
through the same points, arc-length parameterised, with the same limits, from
rest to rest, on 1000 grid points. Prints per scene the durations and their
ratio (ours / toppra's) and exits non-zero when a scene's total is over 1.1x.
"""
import json
import sys

import numpy as np
import toppra
import toppra.algorithm as algo
import toppra.constraint as constraint

LIMIT = 1.1


def toppra_duration(positions, vel, acc):
    q = np.array(positions, dtype=float)
    steps = np.linalg.norm(np.diff(q, axis=0), axis=1)
    keep = np.concatenate([[True], steps > 1e-9])
    q = q[keep]
    if len(q) < 2:
        return 0.0
    ss = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(q, axis=0), axis=1))])
    path = toppra.SplineInterpolator(ss, q)
    vlim = np.column_stack([-vel, vel])
    alim = np.column_stack([-acc, acc])
    cons = [constraint.JointVelocityConstraint(vlim), constraint.JointAccelerationConstraint(alim)]
    grid = np.linspace(0.0, ss[-1], 1000)
    inst = algo.TOPPRA(cons, path, gridpoints=grid, parametrizer="ParametrizeConstAccel")
    traj = inst.compute_trajectory(0.0, 0.0)
    if traj is None:
        raise RuntimeError("toppra found no parameterization")
    return float(traj.duration)


def main():
    scenes = json.load(open(sys.argv[1]))
    print("| scene | ours: reach / approach / close / lift (s) | toppra (s) | total ours | total toppra | ratio |")
    print("|---|---|---|---|---|---|")
    worst = 0.0
    for s in scenes:
        vel = np.array(s["velocity"], dtype=float)
        acc = np.array(s["acceleration"], dtype=float)
        ours = [p["duration"] for p in s["phases"]]
        theirs = [toppra_duration(p["positions"], vel, acc) for p in s["phases"]]
        ratio = sum(ours) / sum(theirs)
        worst = max(worst, ratio)
        print("| {} | {} | {} | {:.2f} | {:.2f} | {:.3f} |".format(
            s["scene"],
            " / ".join(f"{x:.2f}" for x in ours),
            " / ".join(f"{x:.2f}" for x in theirs),
            sum(ours), sum(theirs), ratio))
    print(f"largest ratio ours / toppra: {worst:.3f} (must be at most {LIMIT})")
    sys.exit(0 if worst <= LIMIT else 1)


if __name__ == "__main__":
    main()
