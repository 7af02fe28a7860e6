#!/usr/bin/env python3
"""Reference URDF loading and forward kinematics with yourdfpy (PyPI).

Usage: reference_fk.py CORPUS_DIR OUT.json [PACKAGE_DIR ...]

For every *.urdf under CORPUS_DIR: load it with yourdfpy (meshes not loaded,
package:// resolved through PACKAGE_DIRs), and for 3 joint configurations
(zero, then two seeded random ones) record every link's pose in the root
frame. host/body/tests/corpus.rs loads the same files in Tsukami and compares.
"""
import json, math, os, random, sys, warnings

import numpy as np
import yourdfpy

warnings.filterwarnings("ignore")
corpus, out_path, pkg_dirs = sys.argv[1], sys.argv[2], sys.argv[3:]


def handler(fname, dir=None):
    if fname.startswith("package://"):
        pkg, _, rest = fname[len("package://"):].partition("/")
        for d in pkg_dirs:
            for cand in (os.path.join(d, pkg, rest), os.path.join(d, rest) if os.path.basename(d) == pkg else None):
                if cand and os.path.exists(cand):
                    return cand
    return yourdfpy.filename_handler_magic(fname, dir=dir)


def sample(j, rng):
    lim = j.limit
    if j.type in ("revolute", "prismatic") and lim is not None and lim.lower is not None \
            and lim.upper is not None and lim.lower < lim.upper:
        return rng.uniform(lim.lower, lim.upper)
    return rng.uniform(-math.pi, math.pi) if j.type != "prismatic" else 0.0


results = []
files = sorted(os.path.relpath(os.path.join(r, f), corpus)
               for r, _, fs in os.walk(corpus) for f in fs if f.endswith(".urdf"))
for rel in files:
    entry = {"file": rel, "ok": False}
    try:
        robot = yourdfpy.URDF.load(os.path.join(corpus, rel), load_meshes=False,
                                   build_collision_scene_graph=False, load_collision_meshes=False,
                                   filename_handler=lambda f, d=os.path.dirname(os.path.join(corpus, rel)): handler(f, d))
        root = robot.base_link
        movable = [j for j in robot.robot.joints
                   if j.type in ("revolute", "continuous", "prismatic") and j.mimic is None]
        rng = random.Random(rel)
        configs = []
        for k in range(3):
            q = {j.name: (0.0 if k == 0 else sample(j, rng)) for j in movable}
            robot.update_cfg({n: q[n] for n in robot.actuated_joint_names if n in q})
            poses = {l.name: np.asarray(robot.get_transform(l.name, root)).reshape(-1).tolist()
                     for l in robot.robot.links}
            configs.append({"q": q, "poses": poses})
        entry.update(ok=True, root=root, configs=configs)
    except Exception as e:  # the reference refuses the file
        entry["error"] = f"{type(e).__name__}: {str(e).splitlines()[0][:200] if str(e) else ''}"
    results.append(entry)
json.dump(results, open(out_path, "w"))
ok = sum(r["ok"] for r in results)
print(f"{len(results)} URDF files, {ok} loaded by yourdfpy")
