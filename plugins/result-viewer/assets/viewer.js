// The tsukami result viewer page: the world and the latest plan, live.
// Bodies come from /scene.json (refetched when the world version changes),
// postures, contacts and the panel from the /events stream, the planned
// motion from /trajectory.json. Everything is served by the plugin; nothing
// is fetched from elsewhere.
import * as THREE from 'three';
import { OrbitControls } from '/three/OrbitControls.js';

// What the page shows, for people (title, panel) and for tests.
const view = { generation: -1, worldVersion: -1, plans: 0, motions: 0, shown: -1, frames: 0, error: null };
window.tsukamiViewer = view;

const container = document.getElementById('view');
let renderer;
try {
  renderer = new THREE.WebGLRenderer({ antialias: true, preserveDrawingBuffer: true });
} catch (e) {
  view.error = `no WebGL in this browser: ${e}`;
  document.getElementById('info').textContent = view.error;
  throw e;
}
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setSize(window.innerWidth, window.innerHeight);
container.appendChild(renderer.domElement);

const scene = new THREE.Scene();
scene.background = new THREE.Color(0x1e2228);
const camera = new THREE.PerspectiveCamera(40, window.innerWidth / window.innerHeight, 0.01, 100);
camera.up.set(0, 0, 1);
camera.position.set(1.2, -1.6, 1.6);
scene.add(camera);
scene.add(new THREE.HemisphereLight(0xffffff, 0x404040, 1.2));
const headlight = new THREE.DirectionalLight(0xffffff, 1.6);
headlight.position.set(0.3, 0.5, 1);
camera.add(headlight);
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.set(0.4, -0.2, 0.9);

const bodies = new THREE.Group();   // links, object, obstacles
const marks = new THREE.Group();    // contacts and friction cones
const boxes = new THREE.Group();    // the object's OCP boxes
scene.add(bodies, marks, boxes);
let links = [];                     // one THREE.Group per robot link
let object = null;                  // the object's THREE.Group
let framed = null;                  // the object the camera was aimed at
let state = null;
let trajectory = null;

function material(color) {
  const [r, g, b, a] = color;
  return new THREE.MeshLambertMaterial({
    color: new THREE.Color(r, g, b), flatShading: true, side: THREE.DoubleSide,
    transparent: a < 1, opacity: a, depthWrite: a >= 1,
  });
}

function mesh(solid) {
  const geometry = new THREE.BufferGeometry();
  geometry.setAttribute('position', new THREE.Float32BufferAttribute(solid.positions, 3));
  geometry.setIndex(solid.indices);
  geometry.computeVertexNormals();
  const m = new THREE.Mesh(geometry, material(solid.color));
  m.name = solid.name;
  return m;
}

function place(object3d, p) {
  object3d.position.set(p[0], p[1], p[2]);
  object3d.quaternion.set(p[3], p[4], p[5], p[6]);
}

function clear(group) {
  for (const child of [...group.children]) {
    group.remove(child);
    child.traverse((o) => { if (o.geometry) o.geometry.dispose(); if (o.material) o.material.dispose(); });
  }
}

async function loadScene() {
  const geometry = await (await fetch('/scene.json', { cache: 'no-store' })).json();
  clear(bodies);
  object = null;
  links = geometry.links.map((link) => {
    const g = new THREE.Group();
    g.name = link.name;
    for (const s of link.solids) g.add(mesh(s));
    bodies.add(g);
    return g;
  });
  if (geometry.object) {
    const g = new THREE.Group();
    for (const s of geometry.object.solids) g.add(mesh(s));
    place(g, geometry.object.pose);
    bodies.add(g);
    object = g;
    // A new object (or a moved one) is looked at afresh; the same one keeps
    // the view the user orbited to.
    const key = `${geometry.object.name} ${geometry.object.pose.map((x) => x.toFixed(3))}`;
    if (framed !== key) {
      const p = geometry.object.pose;
      controls.target.set(p[0], p[1], p[2]);
      camera.position.set(p[0] + 0.45, p[1] - 1.0, p[2] + 0.45);
      framed = key;
    }
  }
  for (const s of geometry.obstacles) bodies.add(mesh(s));
  view.worldVersion = geometry.world_version;
}

function showContacts(contacts) {
  clear(marks);
  const height = 0.03;
  for (const c of contacts) {
    const ball = new THREE.Mesh(new THREE.SphereGeometry(0.006, 12, 8), material([0.95, 0.08, 0.08, 1]));
    ball.position.set(...c.position);
    marks.add(ball);
    const cone = new THREE.ConeGeometry(height * c.mu, height, 24, 1, true);
    cone.translate(0, -height / 2, 0);     // apex at the contact, opening along -y
    const m = new THREE.Mesh(cone, material([0.15, 0.85, 0.30, 0.45]));
    const out = new THREE.Vector3(...c.normal).normalize().negate();
    m.quaternion.setFromUnitVectors(new THREE.Vector3(0, -1, 0), out);
    m.position.set(...c.position);
    marks.add(m);
  }
}

// OCP boxes as edges; the one the plan grasped in bright yellow.
function showBoxes(ocp) {
  clear(boxes);
  for (const b of ocp) {
    const edges = new THREE.EdgesGeometry(new THREE.BoxGeometry(...b.extents));
    const lines = new THREE.LineSegments(edges, new THREE.LineBasicMaterial({ color: b.chosen ? 0xffd400 : 0x9a9a60 }));
    lines.position.set(b.pose[0], b.pose[1], b.pose[2]);
    lines.quaternion.set(b.pose[3], b.pose[4], b.pose[5], b.pose[6]).normalize();
    lines.name = `ocp ${b.region}`;
    boxes.add(lines);
  }
}

function posture(poses) {
  if (!poses) return;
  poses.forEach((p, i) => { if (links[i]) place(links[i], p); });
}

const fmt = (x, d = 3) => (typeof x === 'number' ? x.toFixed(d) : '–');
const esc = (s) => String(s).replace(/[&<>"]/g, (c) => ({ '&': '&amp;', '<': '&lt;', '>': '&gt;', '"': '&quot;' }[c]));

function panel(s) {
  const rows = [];
  const row = (k, v, cls = '') => rows.push(`<tr><td>${k}</td><td class="${cls}">${v}</td></tr>`);
  row('world', `v${s.world_version}`);
  const plan = s.plan;
  if (plan && plan.error) row('plan', esc(plan.error), 'error');
  else if (plan) {
    row('grasp type', esc(plan.grasp_type));
    row('OCP region, face', `${esc(plan.ocp_region)} of ${(s.ocp || []).length}, ${esc(plan.face)}`);
    row('margin', `${fmt(plan.margin)}${plan.exact_resists_weight ? ' (holds the weight)' : ''}`);
    row('joints beyond the arm', plan.joints_used.length ? esc(plan.joints_used.join(', ')) : 'none');
    const t = plan.timing_ms;
    row('plan ms', `${fmt(t.total, 1)} (selection ${fmt(t.selection, 1)}, pose ${fmt(t.nominal_pose, 1)}, search ${fmt(t.search, 1)}, verification ${fmt(t.verification, 1)})`);
    row('samples', plan.samples);
  } else row('plan', 'none yet');
  const motion = s.motion;
  if (motion && motion.error) row('motion', esc(motion.error), 'error');
  else if (motion) {
    const stale = motion.world_version !== s.world_version ? ` (in world v${motion.world_version})` : '';
    row('motion', `${fmt(motion.duration, 2)} s, ${motion.points} points, planned in ${fmt(motion.planning_ms, 1)} ms${stale}`);
  }
  if (s.controller) row('controller', `${esc(s.controller.status)} at ${fmt(s.controller.time, 2)} s`);
  if (s.vision) row('vision', `${esc(s.vision.object)}: fit ${fmt(s.vision.fit_error, 4)} m, confidence ${fmt(s.vision.confidence, 2)}`);
  row('results', `${s.counts.plans} plans, ${s.counts.motions} motions`);
  document.getElementById('info').innerHTML = `<table>${rows.join('')}</table>`;
  document.title = `tsukami viewer: ${plan && plan.grasp_type ? plan.grasp_type : 'no plan'} (#${s.counts.plans})`;
}

const slider = document.getElementById('time');
const follow = document.getElementById('follow');
let playing = false;

function showFrame(k) {
  if (!trajectory) return;
  posture(trajectory.frames[k]);
  document.getElementById('clock').textContent =
    `${trajectory.times[k].toFixed(2)} s ${trajectory.phases[k]}`;
}

async function loadTrajectory() {
  const t = await (await fetch('/trajectory.json', { cache: 'no-store' })).json();
  trajectory = t && t.frames && t.frames.length ? t : null;
  document.getElementById('player').style.display = trajectory ? 'flex' : 'none';
  slider.max = trajectory ? trajectory.frames.length - 1 : 0;
  slider.value = 0;
}

slider.addEventListener('input', () => { playing = false; showFrame(Number(slider.value)); });
document.getElementById('play').addEventListener('click', () => {
  if (!trajectory) return;
  playing = !playing;
  if (playing && Number(slider.value) >= trajectory.frames.length - 1) slider.value = 0;
});
follow.addEventListener('change', () => apply(state));

let applying = Promise.resolve();
async function apply(s) {
  if (!s) return;
  state = s;
  try {
    if (s.world_version !== view.worldVersion) await loadScene();
    if (s.counts.motions !== view.motions) {
      view.motions = s.counts.motions;
      await loadTrajectory();
    }
    if (follow.checked && s.controller) posture(s.controller.links);
    else posture(s.posture && s.posture.links);
    showContacts(s.contacts || []);
    showBoxes(s.ocp || []);
    panel(s);
    view.generation = s.generation;
    view.plans = s.counts.plans;
    view.error = null;
  } catch (e) {
    view.error = String(e);
    document.getElementById('info').innerHTML = `<span class="error">${esc(e)}</span>`;
  }
}

// Where a body's box centre is on the page (CSS pixels from the top left):
// `object` or a link name; null when absent. Lets a test look there.
view.screen = (name) => {
  const o = name === 'object' ? object : links.find((l) => l.name === name);
  if (!o) return null;
  const c = new THREE.Box3().setFromObject(o).getCenter(new THREE.Vector3()).project(camera);
  return [(c.x + 1) / 2 * window.innerWidth, (1 - c.y) / 2 * window.innerHeight];
};

const events = new EventSource('/events');
events.addEventListener('state', (e) => {
  const s = JSON.parse(e.data);
  applying = applying.then(() => apply(s));
});

window.addEventListener('resize', () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight);
});

let last = performance.now();
renderer.setAnimationLoop((now) => {
  if (playing && trajectory) {
    const next = Number(slider.value) + 1;
    if (now - last > 1000 / 30) {
      last = now;
      if (next >= trajectory.frames.length) playing = false;
      else { slider.value = next; showFrame(next); }
    }
  }
  controls.update();
  renderer.render(scene, camera);
  view.frames += 1;
  view.shown = view.generation;
});
