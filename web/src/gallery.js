// The gallery page of `diverse gallery`: every motion of a run side by side in 3D.
//
// The data (src/render/gallery.h describes it) is JSON in the page's #gallery-data element:
// models as bodies and geoms in MuJoCo's conventions (z up, quaternions w first), and per
// motion the world position and orientation of every body, sampled at data.fps. One WebGL
// canvas sits behind a grid of tiles; each tile's view is drawn into its own rectangle of
// the canvas (scissor), through one shared camera, so every motion is seen the same way.
// Poses between samples are interpolated (positions linearly, orientations by slerp).
import * as THREE from 'three';
import { OrbitControls } from 'three/examples/jsm/controls/OrbitControls.js';
import { fillPlots } from './plots.js';

const data = JSON.parse(document.getElementById('gallery-data').textContent);
const $ = (id) => document.getElementById(id);

// ---------------------------------------------------------------- formatting

function fmt(x) {
  if (x === null || x === undefined || Number.isNaN(x)) return 'n/a';
  if (x === 0) return '0';
  const a = Math.abs(x);
  if (a >= 1e4 || a < 1e-2) return x.toExponential(2).replace('e+', 'e');
  return x.toPrecision(3);
}
const METRIC_NAMES = {
  hf: 'HF, hands and feet', md: 'MD, mass distance', wja: 'WJA, weighted joint angles',
  shape: 'SHAPE, summed link-length differences (m)',
};
const el = (tag, attrs = {}, text) => {
  const e = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, v);
  if (text !== undefined) e.textContent = text;
  return e;
};

// ---------------------------------------------------------------- robustness

// The robustness suite's kinds of perturbed rollouts, as robustness.json names them and as
// the page shows them (as `diverse robustness` does).
const ROBUST_KINDS = [['parameters', 'params'], ['pushes', 'pushes'], ['friction', 'friction'], ['half_timestep', 'half-step']];
// A whole percentage as C's printf("%.0f") gives it (ties to even), so the page says what
// `diverse robustness` and `diverse report` say.
function percent(held, count) {
  if (!(count > 0)) return 0;
  const x = (100 * held) / count;
  const r = Math.round(x);
  return r - x === 0.5 && r % 2 !== 0 ? r - 1 : r;
}
// ---------------------------------------------------------------- foot slip

// One motion's foot slip (summary.json motions[i].foot_slip, task/foot_slip.h) as a table
// cell: the worst stance's slide in cm, per side in the title.
function slipCell(f) {
  if (!f) return el('td', { class: 'slip self', title: 'foot slip not measured on this motion' }, 'n/a');
  const cm = (v) => (100 * v).toFixed(1);
  const side = (name) => {
    const s = f[name] || {};
    return `${name}: ${s.stances} stances, ${cm(s.mean_per_stance)} cm per stance on average, ` +
      `${cm(s.largest_per_stance)} cm at most, up to ${Number(s.max_speed).toFixed(2)} m/s`;
  };
  return el('td', { class: 'slip', title: `${side('left')}; ${side('right')}` }, `${cm(f.largest_per_stance)} cm`);
}

// One motion's shares (data.robustness.motions[i]) as "holds 5 of 19 (26 %)" and "params
// 0/8, pushes 4/8, friction 0/2, half-step 1/1"; null when the suite was not run on it.
function robustnessOf(i) {
  const r = data.robustness?.motions?.[i];
  if (!r) return null;
  const kinds = ROBUST_KINDS.filter(([k]) => r.kinds?.[k]?.count > 0)
    .map(([k, name]) => `${name} ${r.kinds[k].held}/${r.kinds[k].count}`);
  return {
    total: `holds ${r.held} of ${r.count} (${percent(r.held, r.count)} %)`,
    kinds: kinds.join(', '),
    kindList: kinds,
    percent: percent(r.held, r.count),
    share: r.share,
  };
}
// What the suite is, for the page's help: "8 parameter perturbations at sigma 0.02, ...".
function suiteText(suite) {
  const parts = [];
  if (suite.parameter_samples) parts.push(`${suite.parameter_samples} perturbations of the parameters at sigma ${suite.sigma}`);
  if (suite.push_samples) parts.push(`${suite.push_samples} pushes of ${suite.push_speed} m/s in a ground phase`);
  if ((suite.friction_factors || []).length) parts.push(`friction ${suite.friction_factors.map((f) => `x${f}`).join(' and ')}`);
  if (suite.half_timestep) parts.push('half the timestep');
  return parts.join(', ');
}

// ---------------------------------------------------------------- header

function fillHeader() {
  const run = data.run || {};
  const n = data.motions.length - 1;
  document.title = `${data.task}: ${n} variation${n === 1 ? '' : 's'} (diverse gallery)`;
  $('title').textContent = data.task;
  $('subtitle').textContent =
    `M0 and ${n} variation${n === 1 ? '' : 's'} found by diverse, metric ${(data.metric || '').toUpperCase()}` +
    (run.strategy ? `, ${run.strategy}` : '');
  const bounds = run.bounds || {};
  const facts = [
    ['generations', run.generations], ['evaluations', run.evaluations], ['D', fmt(run.D)],
    ['constraints', run.all_satisfied === undefined ? undefined : run.all_satisfied ? 'all met' : 'not all met'],
    ['strength', run.strength === undefined || run.strength === 1 ? undefined : `${fmt(run.strength)}x gains and torque limits`],
    ['effort bound', bounds.effort === undefined ? undefined : `${fmt(bounds.effort)}x M0's effort`],
    ['distance bound', bounds.distance === undefined ? undefined : `${fmt(bounds.distance)} from M0`],
  ];
  for (const [k, v] of facts) {
    if (v === undefined) continue;
    const d = el('div');
    d.append(el('dt', {}, k), el('dd', {}, String(v)));
    $('facts').append(d);
  }
  for (const note of data.notes || []) $('notes').append(el('li', {}, note));
  const help = $('robustness-help');
  if (data.robustness) {
    const suite = data.robustness.suite || {};
    help.textContent = 'Under each motion, how many of the robustness suite\'s perturbed rollouts still meet the task' +
      (suiteText(suite) ? ` (${suiteText(suite)}${suite.seed !== undefined ? `; seed ${suite.seed}` : ''})` : '') +
      `, from ${data.robustness.source}: a motion that holds few of them sits on a knife edge.`;
  } else {
    help.replaceChildren('The robustness suite was not run on this run\'s motions (a run made before every run ended ' +
      'with it): ', el('code', {}, 'diverse robustness RUN'), ' runs it; then make the gallery again.');
  }
}

// ---------------------------------------------------------------- distance table

function fillDistances() {
  const dist = data.distances || {};
  // The shape distance is listed when the bodies differ (runs with --vary shape), and an
  // objective that combines a motion metric with it ("md+shape") under its own name.
  const combined = typeof dist.objective === 'string' && dist.objective.endsWith('+shape') ? [dist.objective] : [];
  const differ = (d) => d.some((row) => row.some((v) => v > 0));
  const metrics = ['hf', 'md', 'wja', 'shape', ...combined].filter(
    (m) => Array.isArray(dist[m]) && (m !== 'shape' || differ(dist[m])));
  let current = metrics.includes(dist.objective) ? dist.objective : metrics[0];
  const labels = data.motions.map((m) => m.label);
  const draw = () => {
    const table = $('distances');
    table.replaceChildren();
    const head = el('tr');
    const bounds = (data.run || {}).bounds || {};
    const hasEffort = data.motions.some((m) => typeof m.effort_ratio === 'number');
    const hasRobustness = Boolean(data.robustness);
    const hasSlip = data.motions.some((m) => m.foot_slip);
    head.append(el('th', {}, ''), el('th', {}, 'C'));
    if (hasEffort) head.append(el('th', { title: 'control effort relative to M0\'s' }, 'effort'));
    if (hasRobustness) head.append(el('th', { title: 'the share of the robustness suite\'s perturbed rollouts that still meet the task' }, 'holds'));
    if (hasSlip) head.append(el('th', { title: 'how far a planted foot slid in its worst stance' }, 'slide'));
    for (const l of labels) head.append(el('th', {}, l));
    table.append(head);
    const d = dist[current] || [];
    data.motions.forEach((m, i) => {
      const row = el('tr');
      row.append(el('th', {}, m.label));
      const c = el('td', { class: m.constraint === 0 ? 'ok' : 'bad', title: m.status }, fmt(m.constraint));
      row.append(c);
      if (hasEffort) {
        // Effort (time integral of the squared joint torques) as a multiple of M0's.
        const over = bounds.effort !== undefined && m.effort_ratio > bounds.effort;
        row.append(el('td', {
          class: `effort${over ? ' bad' : ''}`,
          title: `effort ${fmt(m.effort)} N²m²s, positive work ${fmt(m.positive_work)} J` +
            (bounds.effort !== undefined ? `; bound ${fmt(bounds.effort)}x M0's` : ''),
        }, `${fmt(m.effort_ratio)}x`));
      }
      if (hasRobustness) {
        const r = robustnessOf(i);
        row.append(r ? el('td', { class: 'robust', title: `${r.total}: ${r.kinds}` }, `${r.percent} %`)
          : el('td', { class: 'robust self', title: 'the robustness suite was not run on this motion' }, 'n/a'));
      }
      if (hasSlip) row.append(slipCell(m.foot_slip));
      const others = (d[i] || []).filter((_, j) => j !== i);
      const min = Math.min(...others);
      (d[i] || []).forEach((v, j) => {
        const cell = el('td', {}, i === j ? '-' : fmt(v));
        if (i === j) cell.className = 'self';
        else if (v === min) cell.className = 'min';
        // A distance bound holds on d(M0, Mi) in the run's own metric.
        if (i !== j && (i === 0 || j === 0) && current === dist.objective &&
            bounds.distance !== undefined && v > bounds.distance) cell.className += ' bad';
        row.append(cell);
      });
      table.append(row);
    });
    $('distance-hint').textContent =
      `d(Mi, Mj) under ${METRIC_NAMES[current] || current}` +
      (current === dist.objective ? ' (the metric the run optimized)' : '') +
      '. In bold, each motion\'s nearest neighbour (dmin). C is the constraint penalty: 0 when the task is met' +
      ((data.run || {}).bounds && Object.keys(data.run.bounds).length ? ' and every bound is kept' : '') + '.' +
      (hasEffort ? ' Effort: the time integral of the squared joint torques, as a multiple of M0\'s' +
        (bounds.effort !== undefined ? ' (red: over the bound)' : '') + '.' : '') +
      (hasRobustness ? ' Holds: the share of the robustness suite\'s perturbed rollouts that still meet the task.' : '') +
      (hasSlip ? ' Slide: how far a planted foot slid in its worst stance (cm), measured by replaying the motion.' : '');
    for (const b of $('metric-tabs').children) b.setAttribute('aria-selected', String(b.dataset.metric === current));
  };
  for (const m of metrics) {
    const b = el('button', { type: 'button', role: 'tab', 'data-metric': m }, m.toUpperCase());
    b.addEventListener('click', () => { current = m; draw(); });
    $('metric-tabs').append(b);
  }
  if (metrics.length) draw();
  else $('distance-panel').hidden = true;
}

// ---------------------------------------------------------------- tracks (what a tile shows)

// A track: one motion's frames on one model.
function makeTrack(source, label) {
  const f = source.frames;
  const track = {
    label,
    model: source.model,
    count: f.count,
    bodies: f.bodies,
    data: Float32Array.from(f.data),
    duration: source.duration,
  };
  track.anchors = followAnchors(track);
  return track;
}

// Where a camera that follows this track looks in each frame: the root body's x and y,
// averaged over half a second either side, so the stride's sway does not shake the view
// (as the videos do; src/render/view_plan.h).
function followAnchors(track) {
  const root = Math.max(0, data.models[track.model].root ?? 0);
  const half = Math.max(1, Math.round(0.5 * data.fps));
  const raw = new Float32Array(2 * track.count);
  for (let k = 0; k < track.count; ++k) {
    const o = (k * track.bodies + root) * 7;
    raw[2 * k] = track.data[o];
    raw[2 * k + 1] = track.data[o + 1];
  }
  const out = new Float32Array(2 * track.count);
  for (let k = 0; k < track.count; ++k) {
    const a = Math.max(0, k - half);
    const b = Math.min(track.count - 1, k + half);
    let x = 0;
    let y = 0;
    for (let j = a; j <= b; ++j) { x += raw[2 * j]; y += raw[2 * j + 1]; }
    out[2 * k] = x / (b - a + 1);
    out[2 * k + 1] = y / (b - a + 1);
  }
  return out;
}

function anchorAt(track, t) {
  const f = Math.min(Math.max(t, 0) * data.fps, track.count - 1);
  const i0 = Math.floor(f);
  const i1 = Math.min(i0 + 1, track.count - 1);
  const a = f - i0;
  const A = track.anchors;
  return new THREE.Vector3(A[2 * i0] + a * (A[2 * i1] - A[2 * i0]), A[2 * i0 + 1] + a * (A[2 * i1 + 1] - A[2 * i0 + 1]), 0);
}

const tiles = data.motions.map((m, i) => {
  const path = (data.paths || [])[i] || null;
  return {
    index: i,
    motion: m,
    main: makeTrack(m, m.label),
    path,
    pathTracks: path ? path.points.map((p) => makeTrack(p, `${m.label} at ${Math.round(p.fraction * 100)} %`)) : [],
    pathIndex: path ? path.points.length - 1 : -1,
  };
});
// The blends of the run's motions (`diverse blend`), when the page has them: one more tile
// plays the precomputed blend nearest to the weights picked in the blend panel.
const blend = data.blend && data.blend.points && data.blend.points.length ? data.blend : null;
if (blend) {
  const blendTracks = blend.points.map((p) => makeTrack(p, p.label));
  tiles.push({
    index: tiles.length,
    motion: { label: 'Blend' },
    blend,
    blendTracks,
    blendIndex: 0,
    main: blendTracks[0],
    path: null,
    pathTracks: [],
    pathIndex: -1,
  });
}
const shownTrack = (tile) => (tile.blend ? tile.blendTracks[tile.blendIndex]
  : tile.pathIndex >= 0 && tile.path ? tile.pathTracks[tile.pathIndex] : tile.main);
const duration = () => Math.max(1e-6, ...tiles.map((t) => shownTrack(t).duration));

// ---------------------------------------------------------------- three.js scene

// The panels that need no WebGL (header, distances, robustness shares, plots) are filled
// before the scene is made, so that a browser without WebGL still shows them.
fillHeader();
fillDistances();
fillPlots(data, $);

const canvas = $('view');
let renderer;
try {
  renderer = new THREE.WebGLRenderer({ canvas, antialias: true, alpha: true, preserveDrawingBuffer: true });
} catch (e) {
  $('webgl-error').hidden = false;
  $('stage').hidden = true;
  $('transport').hidden = true;
  throw e;
}
renderer.setPixelRatio(Math.min(window.devicePixelRatio || 1, 2));
renderer.shadowMap.enabled = true;
renderer.shadowMap.type = THREE.PCFShadowMap;
renderer.setClearColor(0x000000, 0);

const scene = new THREE.Scene();
// Sky: a vertical gradient, pale at the top, bluish at the horizon (as in the film strips).
{
  const sky = document.createElement('canvas');
  sky.width = 2; sky.height = 256;
  const g = sky.getContext('2d');
  const grad = g.createLinearGradient(0, 0, 0, 256);
  grad.addColorStop(0, '#fafbfd');
  grad.addColorStop(1, '#d6e0ec');
  g.fillStyle = grad;
  g.fillRect(0, 0, 2, 256);
  const texture = new THREE.CanvasTexture(sky);
  texture.colorSpace = THREE.SRGBColorSpace;
  scene.background = texture;
}

scene.add(new THREE.HemisphereLight(0xffffff, 0x9a968c, 2.4));
const sun = new THREE.DirectionalLight(0xffffff, 2.5);
sun.castShadow = true;
sun.shadow.mapSize.set(2048, 2048);
sun.shadow.bias = -0.0004;
sun.shadow.normalBias = 0.01;
scene.add(sun, sun.target);

// The extent of everything that moves (to place the floor and the light), and of the
// motions the run found and the landing region (to place the camera: path points that
// fall far away may leave the view, as a zoom out shows).
// Each body's geoms as (offset in the body, radius of a sphere around the geom), so boxes
// cover the bodies themselves (a head reaches well above its body's origin at the neck).
const GEOM_RADIUS = {
  capsule: (s) => s[0] + s[1], sphere: (s) => s[0], ellipsoid: (s) => Math.max(s[0], s[1], s[2]),
  cylinder: (s) => Math.hypot(s[0], s[1]), box: (s) => Math.hypot(s[0], s[1], s[2]),
};
const geomSpheres = data.models.map((model) => model.bodies.map((_, b) => model.geoms
  .filter((g) => g.body === b && GEOM_RADIUS[g.type])
  .map((g) => ({ pos: new THREE.Vector3().fromArray(g.pos), r: GEOM_RADIUS[g.type](g.size) }))));

// Calls visit(point, radius, frame) for every geom of every body in every frame of a track.
function eachGeom(track, visit) {
  const d = track.data;
  const spheres = geomSpheres[track.model];
  const q = new THREE.Quaternion();
  const p = new THREE.Vector3();
  for (let f = 0; f < track.count; ++f) {
    for (let b = 0; b < track.bodies; ++b) {
      const o = (f * track.bodies + b) * 7;
      q.set(d[o + 4], d[o + 5], d[o + 6], d[o + 3]);
      for (const s of spheres[b] || []) {
        p.copy(s.pos).applyQuaternion(q).add(new THREE.Vector3(d[o], d[o + 1], d[o + 2]));
        visit(p, s.r, f);
      }
    }
  }
}

function extent(tracks) {
  const box = new THREE.Box3();
  for (const track of tracks) {
    eachGeom(track, (p, r) => {
      box.expandByPoint(new THREE.Vector3(p.x - r, p.y - r, p.z - r));
      box.expandByPoint(new THREE.Vector3(p.x + r, p.y + r, p.z + r));
    });
  }
  if (box.isEmpty()) box.set(new THREE.Vector3(-1, -0.3, 0), new THREE.Vector3(1, 0.3, 1.6));
  box.expandByScalar(0.05);  // a little air
  return box;
}
// The same box with every pose taken relative to its track's anchor: what a camera that
// follows has to keep in view.
function relativeExtent(tracks) {
  const box = new THREE.Box3();
  for (const track of tracks) {
    eachGeom(track, (p, r, f) => {
      const x = p.x - track.anchors[2 * f];
      const y = p.y - track.anchors[2 * f + 1];
      box.expandByPoint(new THREE.Vector3(x - r, y - r, p.z - r));
      box.expandByPoint(new THREE.Vector3(x + r, y + r, p.z + r));
    });
  }
  if (box.isEmpty()) box.set(new THREE.Vector3(-1, -0.3, 0), new THREE.Vector3(1, 0.3, 1.6));
  box.expandByScalar(0.05);
  return box;
}
const view = data.view || { three_quarter: false, follow: false };
const floorZ = data.models.find((m) => m.floor !== null)?.floor ?? 0;
const motionTiles = tiles.filter((t) => !t.blend);
const bounds = extent(tiles.flatMap((t) => [t.main, ...t.pathTracks, ...(t.blendTracks || [])]));
const globalViewBounds = extent(motionTiles.map((t) => t.main));
const viewBounds = globalViewBounds;
const followBounds = relativeExtent(motionTiles.map((t) => t.main));
followBounds.min.z = Math.min(followBounds.min.z, floorZ);
for (const box of [bounds, viewBounds]) {
  box.min.z = Math.min(box.min.z, floorZ);
  for (const [x0, x1, y = 0, radius = 0] of data.scene?.strips || []) {
    box.expandByPoint(new THREE.Vector3(x0, y - radius, floorZ));
    box.expandByPoint(new THREE.Vector3(x1, y + radius, floorZ));
  }
}
const center = bounds.getCenter(new THREE.Vector3());

// Floor: a plain ground, a track along x banded every 0.5 m, the landing region in green.
// The three layers lie a centimetre apart and are pushed apart in depth as well
// (polygonOffset), so they never fight for the same pixels when seen from afar.
{
  const layer = (color, offset) => new THREE.MeshStandardMaterial({
    color, roughness: 1, polygonOffset: true, polygonOffsetFactor: offset, polygonOffsetUnits: offset });
  const ground = new THREE.Mesh(new THREE.PlaneGeometry(120, 120), layer(0xe9e9e6, 4));
  ground.position.set(center.x, 0, floorZ - 0.01);
  ground.receiveShadow = true;
  scene.add(ground);
  const band = 0.5;
  const light = layer(0xdcdcda, 2);
  const dark = layer(0xc4c4c1, 2);
  // The track is 2 m wide for planar characters; a 3D character may move sideways, so its
  // track spans everything that moves, with a metre to spare on either side.
  const trackY0 = view.three_quarter ? Math.min(-1, bounds.min.y - 1) : -1;
  const trackY1 = view.three_quarter ? Math.max(1, bounds.max.y + 1) : 1;
  const geometry = new THREE.PlaneGeometry(band, trackY1 - trackY0);
  for (let k = Math.floor((bounds.min.x - 6) / band); k < Math.ceil((bounds.max.x + 6) / band); ++k) {
    const tile = new THREE.Mesh(geometry, ((k % 2) + 2) % 2 === 0 ? light : dark);
    tile.position.set((k + 0.5) * band, 0.5 * (trackY0 + trackY1), floorZ - 0.005);
    tile.receiveShadow = true;
    scene.add(tile);
  }
  const green = layer(0x5fb35f, 0);
  // A strip across the track, or a disc (a 3D task's landing point and radius).
  for (const [x0, x1, y = 0, radius = 0] of data.scene?.strips || []) {
    const shape = radius > 0 ? new THREE.CircleGeometry(radius, 64) : new THREE.PlaneGeometry(x1 - x0, 2.2);
    const strip = new THREE.Mesh(shape, green);
    strip.position.set(0.5 * (x0 + x1), y, floorZ);
    strip.receiveShadow = true;
    scene.add(strip);
  }
  // Metre marks along the far edge of the track, facing the camera.
  for (let x = Math.ceil(bounds.min.x - 1); x <= Math.floor(bounds.max.x + 1); ++x) {
    const label = document.createElement('canvas');
    label.width = 128; label.height = 64;
    const g = label.getContext('2d');
    g.fillStyle = '#5b636d';
    g.font = '600 38px system-ui, sans-serif';
    g.textAlign = 'center';
    g.textBaseline = 'middle';
    g.fillText(`${x} m`, 64, 32);
    const texture = new THREE.CanvasTexture(label);
    texture.colorSpace = THREE.SRGBColorSpace;
    const mark = new THREE.Sprite(new THREE.SpriteMaterial({ map: texture, depthWrite: false }));
    mark.scale.set(0.32, 0.16, 1);
    mark.position.set(x, trackY1 + 0.25, floorZ + 0.08);
    scene.add(mark);
  }
}

// ---------------------------------------------------------------- models

function geomMesh(g, material) {
  const [a, b, c] = g.size;
  let geometry;
  switch (g.type) {
    // MuJoCo's capsules and cylinders lie along their local z; three.js's along y.
    case 'capsule': geometry = new THREE.CapsuleGeometry(a, 2 * b, 6, 16).rotateX(Math.PI / 2); break;
    case 'cylinder': geometry = new THREE.CylinderGeometry(a, a, 2 * b, 20).rotateX(Math.PI / 2); break;
    case 'sphere': geometry = new THREE.SphereGeometry(a, 20, 14); break;
    case 'ellipsoid': geometry = new THREE.SphereGeometry(1, 20, 14).scale(a, b, c); break;
    case 'box': geometry = new THREE.BoxGeometry(2 * a, 2 * b, 2 * c); break;
    default: return null;  // meshes and height fields are not exported
  }
  const mesh = new THREE.Mesh(geometry, material);
  mesh.position.fromArray(g.pos);
  mesh.quaternion.set(g.quat[1], g.quat[2], g.quat[3], g.quat[0]);
  mesh.castShadow = true;
  mesh.receiveShadow = true;
  return mesh;
}

function materialFor(rgba, ghost) {
  if (ghost) {
    return new THREE.MeshStandardMaterial({
      color: 0x7f97ba, transparent: true, opacity: 0.28, depthWrite: false, roughness: 0.8 });
  }
  const color = new THREE.Color().setRGB(rgba[0], rgba[1], rgba[2], THREE.SRGBColorSpace);
  return new THREE.MeshStandardMaterial({
    color, roughness: 0.55, metalness: 0.0, transparent: rgba[3] < 1, opacity: rgba[3] });
}

// A rig: one group per body of a model. Rigs are shared by the tiles (each tile poses the
// rig just before its view is drawn), so a model is built once (once more as a ghost).
const rigs = new Map();
let sceneObjectsAdded = false;
function rig(modelIndex, ghost = false) {
  const key = `${modelIndex}:${ghost}`;
  if (rigs.has(key)) return rigs.get(key);
  const model = data.models[modelIndex];
  const root = new THREE.Group();
  const bodies = model.bodies.map(() => new THREE.Group());
  for (const b of bodies) root.add(b);
  const materials = new Map();
  for (const g of model.geoms) {
    const k = g.rgba.join(',');
    if (!materials.has(k)) materials.set(k, materialFor(g.rgba, ghost));
    const mesh = geomMesh(g, materials.get(k));
    if (!mesh) continue;
    if (ghost) mesh.castShadow = false;
    if (g.body < 0) {
      if (!ghost && !sceneObjectsAdded) scene.add(mesh);  // a scene object, drawn once
    } else {
      bodies[g.body].add(mesh);
    }
  }
  if (!ghost) sceneObjectsAdded = true;
  root.visible = false;
  scene.add(root);
  const r = { root, bodies };
  rigs.set(key, r);
  return r;
}

const qa = new THREE.Quaternion();
const qb = new THREE.Quaternion();
function pose(r, track, t) {
  const f = Math.min(Math.max(t, 0) * data.fps, track.count - 1);
  const i0 = Math.floor(f);
  const i1 = Math.min(i0 + 1, track.count - 1);
  const a = f - i0;
  const d = track.data;
  const stride = track.bodies * 7;
  for (let b = 0; b < track.bodies; ++b) {
    const k0 = i0 * stride + b * 7;
    const k1 = i1 * stride + b * 7;
    const body = r.bodies[b];
    body.position.set(
      d[k0] + a * (d[k1] - d[k0]), d[k0 + 1] + a * (d[k1 + 1] - d[k0 + 1]), d[k0 + 2] + a * (d[k1 + 2] - d[k0 + 2]));
    qa.set(d[k0 + 4], d[k0 + 5], d[k0 + 6], d[k0 + 3]);
    qb.set(d[k1 + 4], d[k1 + 5], d[k1 + 6], d[k1 + 3]);
    body.quaternion.slerpQuaternions(qa, qb, a);
  }
}

for (const t of tiles) {
  rig(t.main.model);
  for (const p of [...t.pathTracks, ...(t.blendTracks || [])]) rig(p.model);
  if (t.path) rig(t.main.model, true);
}

// ---------------------------------------------------------------- camera

const camera = new THREE.PerspectiveCamera(30, 1, 0.1, 150);
camera.up.set(0, 0, 1);
const target = center.clone();

// Whether every view follows its own character (a walker); on at first when the run's
// characters travel far (data.view.follow, the film strip's choice).
let following = Boolean(view.follow);

// A planar character is seen from its right (-y), a little ahead and above: a side view
// that keeps a sense of depth. A 3D character is seen three-quarters, from its right and
// front and from above (data.view: MuJoCo's azimuth and elevation, as the film strips).
// The distance fits the whole box in view (as fit_side_camera does); a camera that follows
// fits the poses relative to their anchors and moves with them.
function sideView(aspect) {
  let back;
  if (view.three_quarter) {
    const az = THREE.MathUtils.degToRad(view.azimuth);
    const el = THREE.MathUtils.degToRad(view.elevation);
    back = new THREE.Vector3(-Math.cos(el) * Math.cos(az), -Math.cos(el) * Math.sin(az), -Math.sin(el));
  } else {
    const az = THREE.MathUtils.degToRad(18);
    const el = THREE.MathUtils.degToRad(10);
    back = new THREE.Vector3(Math.sin(az) * Math.cos(el), -Math.cos(az) * Math.cos(el), Math.sin(el));
  }
  const viewBounds = following ? followBounds : globalViewBounds;
  const forward = back.clone().negate();
  const right = new THREE.Vector3().crossVectors(forward, camera.up).normalize();
  const up = new THREE.Vector3().crossVectors(right, forward).normalize();
  const tanV = Math.tan(THREE.MathUtils.degToRad(camera.fov / 2)) * 0.96;
  const tanH = tanV * aspect;
  const middle = viewBounds.getCenter(new THREE.Vector3());
  target.copy(middle);
  let dist = 0.5;
  for (let c = 0; c < 8; ++c) {
    const q = new THREE.Vector3(
      c & 1 ? viewBounds.max.x : viewBounds.min.x, c & 2 ? viewBounds.max.y : viewBounds.min.y,
      c & 4 ? viewBounds.max.z : viewBounds.min.z,
    ).sub(middle);
    dist = Math.max(dist, Math.abs(q.dot(right)) / tanH - q.dot(forward), Math.abs(q.dot(up)) / tanV - q.dot(forward));
  }
  camera.position.copy(middle).addScaledVector(back, dist);
  camera.lookAt(target);
  for (const c of controls) c.update();
}

// The light follows the motions' area so its shadow map stays sharp.
{
  const size = bounds.getSize(new THREE.Vector3());
  const r = 0.6 * Math.max(size.x, size.z, 2);
  sun.position.set(center.x + 1.5, center.y - 2.5, center.z + 6);
  sun.target.position.copy(center);
  Object.assign(sun.shadow.camera, { left: -r, right: r, top: r, bottom: -r, near: 0.5, far: 20 });
  sun.shadow.camera.updateProjectionMatrix();
}

// ---------------------------------------------------------------- tiles (DOM)

const columns = Math.min(tiles.length, tiles.length <= 4 ? tiles.length : tiles.length <= 6 ? 3 : 4);
$('tiles').style.setProperty('--columns', String(columns));
const controls = [];
let needsRender = true;
const requestRender = () => { needsRender = true; };

function statusOf(c, failed, fell) {
  if (c === 0 && !failed) return { text: 'C = 0 · meets the task', ok: true };
  return { text: `C = ${fmt(c)} · ${failed ? 'failed' : fell ? 'fell' : 'misses the task'}`, ok: false };
}

function updateTileText(t) {
  if (t.blend) {
    const b = t.blend.points[t.blendIndex];
    const s = statusOf(b.constraint, b.failed, b.fell);
    t.status.textContent = s.text;
    t.status.className = `status ${s.ok ? 'ok' : 'bad'}`;
    t.dom.classList.toggle('infeasible', !s.ok);
    t.caption.replaceChildren();
    t.caption.append(`${b.label} = ${blendFormula(b.weights)}`);
    return;
  }
  const point = t.path && t.pathIndex >= 0 ? t.path.points[t.pathIndex] : null;
  const s = point && !point.result
    ? statusOf(point.constraint, point.failed, false)
    : statusOf(t.motion.constraint, t.motion.failed, t.motion.fell);
  t.status.textContent = s.text;
  t.status.className = `status ${s.ok ? 'ok' : 'bad'}`;
  t.dom.classList.toggle('infeasible', !s.ok);
  // The suite measured the motion the run returned, not the path's other points.
  if (t.robustLabel) {
    const other = Boolean(point && !point.result);
    t.robustLabel.textContent = other ? `robustness of ${t.motion.label}` : 'robustness';
    t.robust.classList.toggle('other', other);
  }
  if (!point) return;
  const pct = Math.round(point.fraction * 100);
  const where = point.result ? 'the result' : point.generation === 0 ? 'the start (M0)' : `after generation ${point.generation}`;
  t.caption.replaceChildren();
  t.caption.append(`${pct} %: ${where}, d(M0) = ${fmt(point.distance)}, `);
  t.caption.append(el('span', { class: point.feasible ? 'ok' : 'bad' },
    point.feasible ? 'meets the task' : `misses the task (C = ${fmt(point.constraint)})`));
}

for (const t of tiles) {
  const dom = el('div', { class: 'tile', 'data-motion': t.motion.label });
  const head = el('div', { class: 'tile-head' });
  t.status = el('span', { class: 'status' });
  head.append(el('span', { class: 'label' }, t.motion.label), t.status);
  if (!t.blend) {
    // Its shares of the robustness suite, or that the suite was not run (in the foot).
    const r = robustnessOf(t.index);
    t.robust = el('div', { class: `robustness${r ? '' : ' not-run'}` });
    t.robustLabel = el('span', { class: 'robust-label' }, 'robustness');
    t.robust.append(t.robustLabel, ' ');
    if (r) {
      t.robust.append(el('span', { class: `robust-total ${r.share >= 0.75 ? 'ok' : ''}` }, r.total), ': ');
      // Each kind's count kept on one line.
      r.kindList.forEach((k, j) => t.robust.append(j ? ', ' : '', el('span', { class: 'robust-kind' }, k)));
      t.robust.title = 'Perturbed rollouts of this motion that still meet the task (the robustness suite, docs/guide/robustness.md)';
    } else {
      t.robust.append('suite not run');
      t.robust.title = 'No robustness data for this motion: `diverse robustness RUN` measures it';
    }
  }
  const viewport = el('div', { class: 'viewport', 'aria-label': `${t.motion.label} in 3D` });
  const foot = el('div', { class: 'tile-foot' });
  if (t.blend) {
    dom.classList.add('blend');
    t.caption = el('div', { class: 'blend-caption' });
    foot.append(el('div', { class: 'path-title' }, 'The precomputed blend nearest to the weights picked below'), t.caption);
  } else if (t.path && t.path.points.length) {
    const title = el('div', { class: 'path-title' });
    title.append(el('span', {}, 'Optimization path'),
      el('span', {}, `${t.path.points_total} points${t.path.by_index ? ', by step' : ''}`));
    const slider = el('input', {
      type: 'range', class: 'path', min: '0', max: String(t.path.points.length - 1), step: '1',
      value: String(t.path.points.length - 1), 'aria-label': `${t.motion.label} optimization path`,
    });
    const ticks = el('div', { class: 'ticks' });
    for (const p of t.path.points) {
      ticks.append(el('span', {
        class: p.feasible ? '' : 'bad',
        title: p.feasible ? 'meets the task' : `misses the task (C = ${fmt(p.constraint)})`,
      }, `${Math.round(p.fraction * 100)}%${p.feasible ? '' : ' ✗'}`));
    }
    t.caption = el('div', { class: 'path-caption' });
    slider.addEventListener('input', () => {
      t.pathIndex = Number(slider.value);
      updateTileText(t);
      syncScrubber();
      requestRender();
    });
    foot.append(title, slider, ticks, t.caption);
  } else {
    foot.append(el('div', { class: 'm0-note' },
      t.index === 0 ? 'M0, the input motion: every variation starts here and is pushed away from it.'
                    : 'No optimization path in this gallery.'));
  }
  // Under the view, so every tile's view starts at the same height (the blend tile has
  // no such line).
  if (t.robust) foot.prepend(t.robust);
  dom.append(head, viewport, foot);
  $('tiles').append(dom);
  Object.assign(t, { dom, viewport });
  updateTileText(t);

  const c = new OrbitControls(camera, viewport);
  c.target = target;  // one target object shared by every view's controls
  c.enableDamping = false;
  c.addEventListener('change', requestRender);
  controls.push(c);
}

// ---------------------------------------------------------------- blends

// "0.50 M1 + 0.30 M2 + ...": the weights of a blend, largest first, those under 0.005 left out.
function blendFormula(weights) {
  const labels = data.motions.map((m) => m.label);
  return weights.map((w, i) => [w, labels[i]]).filter(([w]) => w >= 0.005).sort((a, b) => b[0] - a[0])
    .map(([w, l]) => `${w.toFixed(2)} ${l}`).join(' + ');
}

// The blend whose weights are nearest (Euclidean) to `weights`; ties go to the first.
function nearestBlend(weights) {
  let best = 0;
  let bestD = Infinity;
  blend.points.forEach((p, k) => {
    let d = 0;
    for (let i = 0; i < weights.length; ++i) d += (p.weights[i] - weights[i]) ** 2;
    if (d < bestD) { bestD = d; best = k; }
  });
  return { index: best, distance: Math.sqrt(bestD) };
}

function fillBlends() {
  const panel = $('blend-panel');
  if (!blend) { panel.hidden = true; return; }
  panel.hidden = false;
  const tile = tiles.find((t) => t.blend);
  const pct = (x) => (x === null || x === undefined ? 'n/a' : `${(100 * x).toFixed(0)} %`);
  const n = data.motions.length;
  let text = `${blend.points.length} blends of M0..M${n - 1}, each the controller at a convex combination of ` +
    `theirs${data.shape ? ' (and a blend of their bodies)' : ''}, weights drawn uniformly: ` +
    `${blend.feasible} meet the task (${pct(blend.feasible_fraction)}).`;
  if (blend.path_points > 0) {
    text += ` Points along the optimization paths, simulated the same way: ${pct(blend.path_feasible_fraction)} of ${blend.path_points}.`;
  }
  $('blend-summary').textContent = text;
  const sliders = [];
  const values = [];
  const weights = () => {
    const raw = sliders.map((s) => Number(s.value));
    const sum = raw.reduce((a, b) => a + b, 0);
    return sum > 0 ? raw.map((v) => v / sum) : raw.map(() => 1 / raw.length);
  };
  const update = () => {
    const w = weights();
    w.forEach((x, i) => { values[i].textContent = x.toFixed(2); });
    const near = nearestBlend(w);
    tile.blendIndex = near.index;
    const b = blend.points[near.index];
    const result = $('blend-result');
    result.replaceChildren();
    result.append(`Playing ${b.label}, ${fmt(near.distance)} from the picked weights: ${blendFormula(b.weights)}; `);
    const ok = b.feasible;
    result.append(el('span', { class: ok ? 'ok' : 'bad' },
      ok ? 'meets the task' : `misses the task (C = ${fmt(b.constraint)})`));
    if (b.nearest !== null && b.nearest !== undefined && Array.isArray(b.distances)) {
      result.append(`; nearest motion ${data.motions[b.nearest].label} (d = ${fmt(b.distances[b.nearest])}, ` +
        `${(data.metric || '').toUpperCase()}).`);
    } else {
      result.append('.');
    }
    result.dataset.blend = b.label;
    updateTileText(tile);
    syncScrubber();
    requestRender();
  };
  const grid = $('blend-weights');
  data.motions.forEach((m, i) => {
    const row = el('label', { class: 'weight' });
    const slider = el('input', { type: 'range', min: '0', max: '100', step: '1', value: '50',
      'aria-label': `weight of ${m.label}`, 'data-motion': m.label });
    const value = el('span', { class: 'weight-value' });
    slider.addEventListener('input', update);
    row.append(el('span', { class: 'weight-label' }, m.label), slider, value);
    grid.append(row);
    sliders.push(slider);
    values.push(value);
  });
  $('blend-equal').addEventListener('click', () => { for (const s of sliders) s.value = '50'; update(); });
  update();
}

// ---------------------------------------------------------------- playback

let time = 0;
// Plays on opening, unless the address ends in #paused.
let playing = !/paused/.test(location.hash);
let last = performance.now();
let holdUntil = 0;
const speed = () => ($('half').checked ? 0.5 : 1);

function syncScrubber() {
  const T = duration();
  time = Math.min(time, T);
  $('time').value = String(Math.round((time / T) * 1000));
  $('clock').textContent = `${time.toFixed(2)} s / ${T.toFixed(2)} s`;
}

$('play').addEventListener('click', () => {
  playing = !playing;
  $('play').textContent = playing ? 'Pause' : 'Play';
  last = performance.now();
});
$('time').addEventListener('input', () => {
  time = (Number($('time').value) / 1000) * duration();
  $('clock').textContent = `${time.toFixed(2)} s / ${duration().toFixed(2)} s`;
  requestRender();
});
$('half').addEventListener('change', () => { last = performance.now(); });
$('reset-view').addEventListener('click', () => { sideView(aspect()); requestRender(); });
$('reset-view').textContent = view.three_quarter ? 'Three-quarter view' : 'Side view';
$('follow').checked = following;
$('follow').addEventListener('change', () => {
  following = $('follow').checked;
  sideView(aspect());
  requestRender();
});
document.addEventListener('keydown', (e) => {
  if (e.code === 'Space' && e.target === document.body) { e.preventDefault(); $('play').click(); }
});

// ---------------------------------------------------------------- drawing

function aspect() {
  const r = tiles[0].viewport.getBoundingClientRect();
  return r.height > 0 ? r.width / r.height : 1;
}

function resize() {
  const stage = $('stage');
  const w = stage.clientWidth;
  const h = stage.clientHeight;
  if (canvas.width !== Math.round(w * renderer.getPixelRatio()) ||
      canvas.height !== Math.round(h * renderer.getPixelRatio())) {
    renderer.setSize(w, h, false);
    needsRender = true;
  }
}

function draw() {
  resize();
  const stageRect = canvas.getBoundingClientRect();
  renderer.setScissorTest(false);
  renderer.clear();
  renderer.setScissorTest(true);
  for (const t of tiles) {
    const r = t.viewport.getBoundingClientRect();
    if (r.bottom < 0 || r.top > window.innerHeight || r.width === 0) continue;
    const x = r.left - stageRect.left;
    const y = stageRect.bottom - r.bottom;
    renderer.setViewport(x, y, r.width, r.height);
    renderer.setScissor(x, y, r.width, r.height);
    camera.aspect = r.width / r.height;
    camera.updateProjectionMatrix();

    for (const r of rigs.values()) r.root.visible = false;
    const track = shownTrack(t);
    // Following: the shared camera moved, for this view only, to the character's anchor.
    const shift = following ? anchorAt(track, time) : null;
    if (shift) { camera.position.add(shift); camera.updateMatrixWorld(); }
    const main = rig(track.model);
    pose(main, track, time);
    main.root.visible = true;
    const point = t.path && t.pathIndex >= 0 ? t.path.points[t.pathIndex] : null;
    if (point && !point.result) {  // the result as a faint figure, for comparison
      const ghost = rig(t.main.model, true);
      pose(ghost, t.main, time);
      ghost.root.visible = true;
    }
    renderer.render(scene, camera);
    if (shift) { camera.position.sub(shift); camera.updateMatrixWorld(); }
  }
}

function frame(now) {
  // A frame's time stamp is when the frame began, which can come before `last` (play
  // pressed, or the speed changed, within the frame): never a step backwards.
  const dt = Math.max(0, Math.min((now - last) / 1000, 0.1));
  last = now;
  if (playing) {
    const T = duration();
    if (time >= T) {
      if (!holdUntil) holdUntil = now + 600;  // hold the end a moment before looping
      if (now >= holdUntil) { time = 0; holdUntil = 0; }
    } else {
      time = Math.min(T, time + dt * speed());
    }
    syncScrubber();
    needsRender = true;
  }
  if (needsRender) {
    needsRender = false;
    draw();
    if (!document.body.dataset.ready) document.body.dataset.ready = '1';
  }
  requestAnimationFrame(frame);
}

fillBlends();
$('play').textContent = playing ? 'Pause' : 'Play';
new ResizeObserver(requestRender).observe($('stage'));
window.addEventListener('scroll', requestRender, { passive: true });
sideView(aspect());
syncScrubber();
requestAnimationFrame(frame);
