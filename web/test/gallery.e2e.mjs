// End-to-end test of a run's gallery page and BVH export, in headless Chromium with no
// network (tests/e2e/gallery_e2e.sh makes the run, its gallery.html and export/*.bvh).
//
//   node test/gallery.e2e.mjs RUN_DIR
//
// Checks: the page loads from a file:// URL and requests nothing else; it logs no errors;
// the canvas draws (its pixels are not uniform); moving the time scrubber and a path slider
// change the picture; infeasible path points are marked; the first BVH file loads with
// three.js's BVHLoader with one joint per moving body and one frame per 1/30 s of motion,
// and its forward kinematics (as three.js plays it) puts every joint within 1 mm of the
// body's position in the page's data (MuJoCo's xpos). The plots panel draws D and the best
// set's D with one point per generation of the data, C and dmin for every motion, one
// heatmap per metric with a cell per pair. A run with bounds shows every motion's effort
// relative to M0's, marked where over the bound, and its bounds. A 3D run (free root) is seen three-quarters and
// its "follow" switch moves the views. Where RUN_DIR/export holds glTF files: every .glb
// passes the Khronos glTF validator with no error, three.js's GLTFLoader reads each as a
// SkinnedMesh with a bone per body and its animation, and playing it with an AnimationMixer
// puts every bone and a vertex of each within 1 mm of MuJoCo's bodies; all.glb is drawn in Chromium by a small three.js viewer (its pixels are not
// uniform). With blends (`diverse blend`): one blend tile and one weight slider per motion;
// for every blend, its own weights on the sliders bring up the blend nearest to them (as
// the test computes it), marked as meeting the task or not as its constraint says; two
// corners of the simplex show different pictures. Writes RUN_DIR/gallery-screenshot.png, plots-screenshot.png and
// gltf-screenshot.png. Every motion shows its shares of the robustness suite (robustness.json
// or summary.json), or, for a run without them, that the suite was not run. With WebGL
// turned off the page says so and still shows its header, distance table and plots. Chromium:
// $CHROMIUM or /usr/bin/chromium.
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { pathToFileURL } from 'node:url';
import { chromium } from 'playwright-core';
import * as THREE from 'three';
import { BVHLoader } from 'three/examples/jsm/loaders/BVHLoader.js';
import { GLTFLoader } from 'three/examples/jsm/loaders/GLTFLoader.js';
import { existsSync, readdirSync, writeFileSync } from 'node:fs';
import { dirname } from 'node:path';
import { fileURLToPath } from 'node:url';
import validator from 'gltf-validator';

const runDir = resolve(process.argv[2] ?? '');
if (!process.argv[2]) {
  console.error('usage: node test/gallery.e2e.mjs RUN_DIR');
  process.exit(2);
}
const executablePath = process.env.CHROMIUM || '/usr/bin/chromium';

let passed = 0;
let failed = 0;
function check(ok, what, detail = '') {
  if (ok) {
    passed++;
    console.log(`ok - ${what}`);
  } else {
    failed++;
    console.log(`FAIL - ${what}${detail ? `: ${detail}` : ''}`);
  }
}

// ---------------------------------------------------------------- the page

const userDataDir = mkdtempSync(join(tmpdir(), 'diverse-e2e-chromium-'));
const context = await chromium.launchPersistentContext(userDataDir, {
  executablePath,
  headless: true,
  viewport: { width: 1400, height: 1100 },
  args: [
    '--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync',
    // WebGL on the CPU: Chromium's SwiftShader must be allowed explicitly without a GPU.
    '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
  ],
});
const errors = [];
const outside = [];
try {
  await context.route('**/*', (route) => {
    const url = route.request().url();
    if (url.startsWith('file://')) return route.continue();
    outside.push(url);
    return route.abort();
  });
  const page = await context.newPage();
  page.on('console', (m) => { if (m.type() === 'error') errors.push(`console: ${m.text()}`); });
  page.on('pageerror', (e) => errors.push(`pageerror: ${e.message}`));
  page.on('requestfailed', (r) => {
    if (!r.url().startsWith('file://')) return;
    errors.push(`request failed: ${r.url()} (${r.failure()?.errorText})`);
  });

  // Opened paused (#paused): software WebGL is slow, and a still page answers at once.
  const url = `${pathToFileURL(join(runDir, 'gallery.html')).href}#paused`;
  await page.goto(url);
  await page.waitForSelector('body[data-ready="1"]', { timeout: 30000 });
  check(true, 'gallery.html loads and draws its first frame');
  check((await page.textContent('#play')).trim() === 'Play', 'the page opens paused when asked (#paused)');
  // Two clicks in one task, so no slow frame is drawn in between.
  const labels = await page.evaluate(() => {
    const b = document.getElementById('play');
    b.click();
    const first = b.textContent;
    b.click();
    return [first, b.textContent];
  });
  check(labels[0] === 'Pause' && labels[1] === 'Play', 'the play/pause button plays and pauses', labels.join(', '));

  const data = await page.evaluate(() => JSON.parse(document.getElementById('gallery-data').textContent));
  check(await page.locator('.tile:not(.blend)').count() === data.motions.length, 'one tile per motion',
    `${await page.locator('.tile:not(.blend)').count()} tiles, ${data.motions.length} motions`);
  check(await page.locator('.tile.blend').count() === (data.blend ? 1 : 0),
    data.blend ? 'one tile plays the blends' : 'no blend tile without blends');

  // Two animation frames, so what was asked for is on the canvas.
  const settle = () => page.evaluate(() => new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r))));
  // Pixel statistics of the WebGL canvas; `keep` stores the pixels to compare the next call with.
  const snapshot = () => page.evaluate(() => {
    const c = document.getElementById('view');
    const copy = document.createElement('canvas');
    copy.width = c.width;
    copy.height = c.height;
    const g = copy.getContext('2d');
    g.drawImage(c, 0, 0);
    const px = g.getImageData(0, 0, c.width, c.height).data;
    const colours = new Set();
    let changed = 0;
    const before = window.__lastPixels;
    for (let i = 0; i < px.length; i += 4) {
      if (colours.size < 5000) colours.add((px[i] << 16) | (px[i + 1] << 8) | px[i + 2]);
      if (before && (before[i] !== px[i] || before[i + 1] !== px[i + 1] || before[i + 2] !== px[i + 2])) changed++;
    }
    window.__lastPixels = px;
    return { colours: colours.size, changed, width: c.width, height: c.height };
  });

  await page.locator('#time').fill('0');
  await settle();
  const start = await snapshot();
  check(start.width > 0 && start.colours > 100, 'the canvas draws (pixels not uniform)',
    `${start.colours} distinct colours in ${start.width}x${start.height}`);

  await page.locator('#time').fill('450');
  await settle();
  const middle = await snapshot();
  check(middle.changed > 2000, 'moving the time scrubber changes the picture', `${middle.changed} pixels changed`);
  const clock = await page.textContent('#clock');
  const [shown, total] = (clock.match(/^(\d+\.\d\d) s \/ (\d+\.\d\d) s$/) || []).slice(1).map(Number);
  check(total > 0 && Math.abs(shown - 0.45 * total) <= 0.011, 'the clock shows the scrubbed time (45 %)', clock);

  // An animation frame's time stamp is when the frame began, which can come before the
  // moment play was pressed: the clock must not run backwards (it did, to a negative time).
  const early = await page.evaluate(async () => {
    const scrubber = document.getElementById('time');
    scrubber.value = '0';
    scrubber.dispatchEvent(new Event('input'));
    const real = performance.now.bind(performance);
    performance.now = () => real() + 1000;  // play pressed "1 s after" the next frames begin
    document.getElementById('play').click();
    performance.now = real;
    await new Promise((r) => requestAnimationFrame(() => requestAnimationFrame(r)));
    const text = document.getElementById('clock').textContent;
    document.getElementById('play').click();
    return text;
  });
  check(/^\d/.test(early), 'the clock never runs backwards', early);
  await page.locator('#time').fill('450');
  await settle();

  // A path slider: from the result (100 %) to a point whose motion differs from it.
  const v = data.paths.findIndex((p) => p && p.points.length > 1);
  if (data.paths.length > 0) check(v > 0, 'the page has an optimization path with several points');
  if (v > 0) {
    const points = data.paths[v].points;
    const last = points[points.length - 1];
    const other = points.findIndex((p) => p.frames.data.some((x, i) => x !== last.frames.data[i]) ||
                                          p.frames.count !== last.frames.count);
    check(other >= 0, `M${v}'s path points differ in motion`);
    const slider = page.locator('input.path').nth(v - 1);
    const tile = page.locator(`.tile[data-motion="M${v}"]`);
    const captionBefore = await tile.locator('.path-caption').textContent();
    await slider.fill(String(Math.max(other, 0)));
    await settle();
    const moved = await snapshot();
    check(moved.changed > 500, 'moving a path slider changes the picture', `${moved.changed} pixels changed`);
    const captionAfter = await tile.locator('.path-caption').textContent();
    check(captionAfter !== captionBefore, 'the path caption follows the slider', `${captionBefore} -> ${captionAfter}`);
    // Every point is marked as meeting the task or not, as its constraint says.
    let marks = 0;
    for (let k = 0; k < points.length; ++k) {
      await slider.fill(String(k));
      const infeasible = await tile.evaluate((e) => e.classList.contains('infeasible'));
      const caption = await tile.locator('.path-caption').textContent();
      const expected = !points[k].feasible;
      if (infeasible === expected && caption.includes(expected ? 'misses the task' : 'meets the task')) marks++;
    }
    check(marks === points.length, 'infeasible path points are marked (C > 0)', `${marks} of ${points.length}`);
    await slider.fill(String(points.length - 1));
  }

  // ---------------------------------------------------------------- blends

  if (data.blend) {
    const blends = data.blend.points;
    const n = data.motions.length;
    const sliders = page.locator('#blend-weights input[type=range]');
    check(await sliders.count() === n, 'the blend panel has one weight slider per motion', `${await sliders.count()} sliders`);
    check(blends.every((b) => b.weights.length === n && Math.abs(b.weights.reduce((a, x) => a + x, 0) - 1) < 1e-9),
      'every blend has one weight per motion, summing to 1');
    const summary = await page.textContent('#blend-summary');
    check(summary.includes(`${blends.length} blends`) && summary.includes(`${data.blend.feasible} meet the task`),
      'the blend panel says how many blends meet the task', summary);
    // The same rule as the page: slider values scaled to sum 1, the nearest blend's weights.
    const expectedNearest = (values) => {
      const sum = values.reduce((a, x) => a + x, 0);
      const w = values.map((x) => (sum > 0 ? x / sum : 1 / n));
      let best = 0;
      let bestD = Infinity;
      blends.forEach((b, k) => {
        const d = b.weights.reduce((a, x, i) => a + (x - w[i]) ** 2, 0);
        if (d < bestD) { bestD = d; best = k; }
      });
      return best;
    };
    const blendTile = page.locator('.tile.blend');
    // All sliders at once, then one input event (the page reads every slider on each).
    const setWeights = (values) => page.evaluate((v) => {
      const inputs = [...document.querySelectorAll('#blend-weights input[type=range]')];
      inputs.forEach((s, i) => { s.value = String(v[i]); });
      inputs[0].dispatchEvent(new Event('input', { bubbles: true }));
    }, values);
    // Each blend's own weights (as the sliders can hold them) bring up the blend the page
    // should pick, marked as meeting the task or not as its constraint value says.
    let right = 0;
    const seen = new Set();
    for (const b of blends) {
      const values = b.weights.map((w) => Math.round(100 * w));
      await setWeights(values);
      const want = blends[expectedNearest(values)];
      seen.add(want.label);
      const shown = await page.locator('#blend-result').getAttribute('data-blend');
      const infeasible = await blendTile.evaluate((e) => e.classList.contains('infeasible'));
      const result = await page.textContent('#blend-result');
      const status = await blendTile.locator('.status').textContent();
      if (shown === want.label && infeasible === !want.feasible &&
          result.includes(want.feasible ? 'meets the task' : 'misses the task') &&
          status.includes(want.feasible ? 'meets the task' : want.failed ? 'failed' : want.fell ? 'fell' : 'misses the task')) right++;
    }
    check(right === blends.length, 'picking weights plays the nearest blend, marked as meeting the task or not',
      `${right} of ${blends.length}`);
    check(seen.size > 1, 'different weights bring up different blends', [...seen].join(' '));
    // Weight on one motion alone, then on another: the blend view changes.
    const corner = (i) => Array.from({ length: n }, (_, j) => (j === i ? 100 : 0));
    const a = expectedNearest(corner(0));
    const other = [...Array(n).keys()].find((i) => expectedNearest(corner(i)) !== a);
    if (other !== undefined) {
      // Through the sliders themselves, as a user moves them.
      const fillWeights = async (values) => {
        for (let i = 0; i < n; ++i) await sliders.nth(i).fill(String(values[i]));
      };
      await page.locator('#time').fill('600');
      await fillWeights(corner(0));
      await settle();
      await snapshot();
      await fillWeights(corner(other));
      await settle();
      const moved = await snapshot();
      check(moved.changed > 300, 'moving the weights to another corner changes the blend\'s picture', `${moved.changed} pixels changed`);
      const shownLabel = await page.locator('#blend-result').getAttribute('data-blend');
      check(shownLabel === blends[expectedNearest(corner(other))].label, 'the sliders pick the blend nearest to their weights',
        `${shownLabel}, expected ${blends[expectedNearest(corner(other))].label}`);
    }
    await page.locator('#blend-equal').click();
  } else {
    check(await page.locator('#blend-panel').isHidden(), 'a gallery without blends hides the blend panel');
  }

  // ---------------------------------------------------------------- 3D: the view

  const three = Boolean(data.view && data.view.three_quarter);
  check((await page.textContent('#reset-view')).trim() === (three ? 'Three-quarter view' : 'Side view'),
    `the view button names the ${three ? 'three-quarter' : 'side'} view`);
  const following = await page.locator('#follow').isChecked();
  check(following === Boolean(data.view && data.view.follow), `"follow" starts ${following ? 'on (the characters travel far)' : 'off'}`);
  if (three) {
    await page.locator('#time').fill('700');
    await settle();
    await snapshot();
    await page.locator('#follow').setChecked(!following);
    await settle();
    const switched = await snapshot();
    check(switched.changed > 500, 'switching "follow" moves the views', `${switched.changed} pixels changed`);
    await page.locator('#follow').setChecked(following);
  }

  // ---------------------------------------------------------------- the plots panel

  const plots = await page.evaluate(() => {
    const series = (id) => [...document.querySelectorAll(`#${id} path.series`)].map((p) => ({
      name: p.dataset.series, points: Number(p.dataset.points), d: p.getAttribute('d') }));
    return {
      d: series('plot-d'), c: series('plot-c'), dmin: series('plot-dmin'),
      heatmaps: [...document.querySelectorAll('#heatmaps .heatmap-box')].map((b) => ({
        metric: b.dataset.metric, cells: b.querySelectorAll('rect.cell').length })),
      progressHidden: document.getElementById('progress-panel').hidden,
    };
  });
  const progress = data.progress || {};
  const n = data.motions.length;
  if ((progress.generation || []).length > 0) {
    const g = progress.generation.length;
    check(plots.d.length === 2 && plots.d.every((p) => p.points === g && (p.d.match(/[ML]/g) || []).length === g),
      'the plots draw D and the best set\'s D at every generation', JSON.stringify(plots.d.map((p) => [p.name, p.points])));
    check(plots.c.length === n - 1 && plots.dmin.length === n,
      'the plots draw C of every variation and dmin of every motion', `${plots.c.length} C, ${plots.dmin.length} dmin`);
    const last = progress.best_D[g - 1];
    check(Math.abs(last - data.run.D) <= 1e-9 * Math.max(1, Math.abs(data.run.D)),
      'the best set\'s D at the last generation is the run\'s D', `${last} vs ${data.run.D}`);
  } else {
    check(plots.progressHidden, 'a run without log.jsonl hides the progress plots');
  }
  const objective = data.distances?.objective;
  const combined = typeof objective === 'string' && objective.endsWith('+shape') ? [objective] : [];
  const metrics = ['hf', 'md', 'wja', 'shape', ...combined].filter((k) => Array.isArray(data.distances?.[k]) &&
    (k !== 'shape' || data.distances[k].some((row) => row.some((x) => x > 0))));
  check(plots.heatmaps.length === metrics.length && plots.heatmaps.every((h) => h.cells === n * n),
    'one distance heatmap per metric, one cell per pair', JSON.stringify(plots.heatmaps));
  if (!plots.progressHidden) {
    await page.locator('#plots').screenshot({ path: join(runDir, 'plots-screenshot.png') });
  }

  // A run with bounds: every motion's effort relative to M0's in the distance table (marked
  // where over the bound) and the bounds among the run's facts.
  const bounds = data.run?.bounds || {};
  if (Object.keys(bounds).length) {
    const shown = await page.evaluate(() => ({
      head: [...document.querySelectorAll('#distances tr:first-child th')].map((t) => t.textContent),
      effort: [...document.querySelectorAll('#distances td.effort')].map((t) => ({
        text: t.textContent, over: t.classList.contains('bad') })),
      facts: document.getElementById('facts').textContent,
    }));
    check(shown.head.includes('effort') && shown.effort.length === n &&
      shown.effort.every((e, i) => Math.abs(parseFloat(e.text) - data.motions[i].effort_ratio) <=
        0.01 * data.motions[i].effort_ratio),
      'the distance table shows every motion\'s effort relative to M0\'s', JSON.stringify(shown.effort));
    check(shown.effort[0].text.startsWith('1') && shown.effort.every((e, i) =>
      e.over === (bounds.effort !== undefined && data.motions[i].effort_ratio > bounds.effort)),
      'efforts over the bound are marked, the others not', JSON.stringify(shown.effort));
    check((bounds.effort === undefined || shown.facts.includes('effort bound')) &&
      (bounds.distance === undefined || shown.facts.includes('distance bound')),
      'the run\'s bounds are among its facts', shown.facts);
  }

  // ---------------------------------------------------------------- robustness

  // Every motion's shares of the robustness suite beside its other figures, as the run
  // wrote them (RUN/robustness.json, else summary.json "robustness"); a run without them
  // (made before every run ended with the suite) says on every motion that it was not run.
  const robustFile = join(runDir, 'robustness.json');
  const summary = JSON.parse(readFileSync(join(runDir, 'summary.json'), 'utf8'));
  const measured = existsSync(robustFile) ? JSON.parse(readFileSync(robustFile, 'utf8')) : summary.robustness;
  const robustShown = await page.evaluate(() => ({
    tiles: [...document.querySelectorAll('.tile:not(.blend)')].map((t) => t.querySelector('.robustness')?.textContent ?? ''),
    column: [...document.querySelectorAll('#distances td.robust')].map((t) => t.textContent),
    notes: document.getElementById('notes').textContent,
    help: document.getElementById('robustness-help').textContent,
  }));
  if (measured) {
    // printf's %.0f: ties to even.
    const pct = (h, c) => { const x = (100 * h) / c; const r = Math.round(x); return r - x === 0.5 && r % 2 ? r - 1 : r; };
    const names = [['parameters', 'params'], ['pushes', 'pushes'], ['friction', 'friction'], ['half_timestep', 'half-step']];
    const expected = data.motions.map((m) => {
      const r = measured.motions.find((x) => x.label === m.label);
      if (!r) return null;
      const kinds = names.filter(([k]) => r.kinds[k].count > 0).map(([k, name]) => `${name} ${r.kinds[k].held}/${r.kinds[k].count}`);
      return { text: `holds ${r.held} of ${r.count} (${pct(r.held, r.count)} %): ${kinds.join(', ')}`, cell: `${pct(r.held, r.count)} %` };
    });
    check(expected.every((e, i) => e && robustShown.tiles[i].includes(e.text)),
      'every motion shows its shares of the robustness suite, over all and by kind',
      JSON.stringify({ shown: robustShown.tiles, expected: expected.map((e) => e?.text) }));
    check(robustShown.column.length === data.motions.length && expected.every((e, i) => robustShown.column[i] === e.cell),
      'the distance table shows every motion\'s share of the suite', JSON.stringify(robustShown.column));
    check(!robustShown.notes.includes('robustness suite not run') && robustShown.help.includes('robustness suite'),
      'the page says what the suite is', robustShown.help);
  } else {
    check(robustShown.tiles.length === data.motions.length && robustShown.tiles.every((t) => t.includes('suite not run')),
      'a run without robustness data says on every motion that the suite was not run', JSON.stringify(robustShown.tiles));
    check(robustShown.column.length === 0, 'and has no robustness column in the distance table');
    check(robustShown.notes.includes('robustness suite not run') && robustShown.help.includes('was not run'),
      'and says how to run it', `${robustShown.notes} | ${robustShown.help}`);
  }

  // ---------------------------------------------------------------- foot slip

  // Every motion's worst stance's slide (summary.json motions[i].foot_slip) in the distance
  // table, per side in its title; a run without the measure has no such column.
  const slipShown = await page.evaluate(() =>
    [...document.querySelectorAll('#distances td.slip')].map((t) => ({ text: t.textContent, title: t.title })));
  const slips = (summary.motions || []).map((m) => m.foot_slip);
  if (slips.some(Boolean)) {
    check(slipShown.length === data.motions.length && slips.every((f, i) =>
      f && slipShown[i].text === `${(100 * f.largest_per_stance).toFixed(1)} cm` &&
      slipShown[i].title.includes(`left: ${f.left.stances} stances`)),
    'the distance table shows every motion\'s foot slip', JSON.stringify(slipShown));
  } else {
    check(slipShown.length === 0, 'a run without the foot-slip measure has no slide column', JSON.stringify(slipShown));
  }

  await page.locator('#time').fill('500');
  await settle();
  await page.screenshot({ path: join(runDir, 'gallery-screenshot.png'), fullPage: true });

  check(errors.length === 0, 'the page logs no errors', errors.join(' | '));
  check(outside.length === 0, 'the page requests nothing but its own file', outside.join(' '));

  // ---------------------------------------------------------------- BVH in three.js

  const motion = data.motions[0];
  const model = data.models[motion.model];
  const text = readFileSync(join(runDir, 'export', 'm0.bvh'), 'utf8');
  const { skeleton, clip } = new BVHLoader().parse(text);
  const joints = skeleton.bones.filter((b) => b.name !== 'ENDSITE');
  check(joints.length === model.bodies.length, 'BVHLoader: one joint per moving body',
    `${joints.length} joints, ${model.bodies.length} bodies`);
  const frames = clip.tracks[0].times.length;
  check(frames === motion.frames.count, 'BVHLoader: one frame per 1/30 s of the motion',
    `${frames} frames, ${motion.frames.count} expected`);

  // Play the clip in three.js and compare joint positions with MuJoCo's body positions
  // (BVH axes: (x, z, -y) of MuJoCo's).
  const root = skeleton.bones[0];
  const mixer = new THREE.AnimationMixer(root);
  // Played once and held, so the last frame's time does not wrap back to the first.
  mixer.clipAction(clip).setLoop(THREE.LoopOnce, 1).play().clampWhenFinished = true;
  const byName = new Map(joints.map((b) => [b.name, b]));
  let worst = 0;
  for (const k of [0, Math.floor(frames / 3), Math.floor((2 * frames) / 3), frames - 1]) {
    mixer.setTime(clip.tracks[0].times[k]);
    root.updateMatrixWorld(true);
    model.bodies.forEach((body, b) => {
      const bone = byName.get(body.name);
      if (!bone) { worst = Infinity; return; }
      const p = new THREE.Vector3().setFromMatrixPosition(bone.matrixWorld);
      const o = (k * motion.frames.bodies + b) * 7;
      const d = motion.frames.data;
      worst = Math.max(worst, p.distanceTo(new THREE.Vector3(d[o], d[o + 2], -d[o + 1])));
    });
  }
  check(worst < 1e-3, 'BVHLoader: joints within 1 mm of MuJoCo\'s body positions', `worst ${(worst * 1000).toFixed(3)} mm`);

  // ---------------------------------------------------------------- glTF

  const exportDir = join(runDir, 'export');
  const glbs = existsSync(exportDir) ? readdirSync(exportDir).filter((f) => f.endsWith('.glb')).sort() : [];
  if (glbs.length > 0) {
    check(glbs.length === data.motions.length + 1, 'one .glb per motion and all.glb', glbs.join(' '));
    for (const file of glbs) {
      const bytes = new Uint8Array(readFileSync(join(exportDir, file)));
      const report = await validator.validateBytes(bytes);
      const errors = report.issues.messages.filter((m) => m.severity === 0);
      const warnings = report.issues.messages.filter((m) => m.severity === 1);
      check(report.issues.numErrors === 0 && warnings.length === 0, `glTF validator: ${file} has no errors or warnings`,
        [...errors, ...warnings].slice(0, 5).map((m) => `${m.code} ${m.pointer || ''} ${m.message}`).join(' | '));
    }
    // Each motion's file in three.js: a node per body, its animation played back against
    // MuJoCo's body positions (glTF axes: (x, z, -y) of MuJoCo's).
    let worstGltf = 0, worstSkin = 0, skinnedChecks = 0;
    for (const [i, motion] of data.motions.entries()) {
      const bytes = readFileSync(join(exportDir, `m${i}.glb`));
      const gltf = await new Promise((ok, fail) => new GLTFLoader().parse(
        bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength), '', ok, fail));
      const model = data.models[motion.model];
      const byName = new Map();
      gltf.scene.traverse((o) => { if (o.name) byName.set(o.name, o); });
      const missing = model.bodies.filter((b) => !byName.has(b.name.replace(/[.\s]/g, '_')) && !byName.has(b.name));
      check(missing.length === 0, `GLTFLoader: ${motion.label} has a node per body`, missing.map((b) => b.name).join(' '));
      check(gltf.animations.length === 1, `GLTFLoader: ${motion.label} has its animation`);
      // The character is one SkinnedMesh over a bone per body (the skin's joints in body order).
      let skinned = null;
      gltf.scene.traverse((o) => { if (o.isSkinnedMesh) skinned = o; });
      check(skinned !== null && skinned.skeleton.bones.length === model.bodies.length &&
            skinned.skeleton.bones.every((bone, b) => bone.name === byName.get(model.bodies[b].name)?.name),
            `GLTFLoader: ${motion.label} is a SkinnedMesh with a bone per body`,
            skinned ? skinned.skeleton.bones.map((bone) => bone.name).join(' ') : 'none');
      // One vertex bound to each bone.
      const vertexOf = new Map();
      if (skinned) {
        const index = skinned.geometry.attributes.skinIndex;
        for (let v = 0; v < index.count; v++) if (!vertexOf.has(index.getX(v))) vertexOf.set(index.getX(v), v);
      }
      const mixer = new THREE.AnimationMixer(gltf.scene);
      const clip = gltf.animations[0];
      mixer.clipAction(clip).setLoop(THREE.LoopOnce, 1).play().clampWhenFinished = true;
      const count = motion.frames.count;
      for (const k of [0, Math.floor(count / 2), count - 1]) {
        mixer.setTime(k / data.fps);
        gltf.scene.updateMatrixWorld(true);
        model.bodies.forEach((body, b) => {
          const node = byName.get(body.name) || byName.get(body.name.replace(/[.\s]/g, '_'));
          if (!node) return;
          const p = new THREE.Vector3().setFromMatrixPosition(node.matrixWorld);
          const o = (k * motion.frames.bodies + b) * 7;
          const d = motion.frames.data;
          worstGltf = Math.max(worstGltf, p.distanceTo(new THREE.Vector3(d[o], d[o + 2], -d[o + 1])));
          // The skinned vertex, as three.js deforms it, against the body's pose in MuJoCo
          // applied to the vertex's place in its body (its bind position through the bone's
          // inverse bind matrix).
          const v = vertexOf.get(b);
          if (skinned && v !== undefined) {
            const bind = new THREE.Vector3().fromBufferAttribute(skinned.geometry.attributes.position, v);
            const drawn = skinned.applyBoneTransform(v, bind.clone());
            const body = new THREE.Matrix4().compose(new THREE.Vector3(d[o], d[o + 2], -d[o + 1]),
              new THREE.Quaternion(d[o + 4], d[o + 6], -d[o + 5], d[o + 3]).normalize(), new THREE.Vector3(1, 1, 1));
            const expected = bind.clone().applyMatrix4(skinned.skeleton.boneInverses[b]).applyMatrix4(body);
            worstSkin = Math.max(worstSkin, drawn.distanceTo(expected));
            skinnedChecks++;
          }
        });
      }
    }
    check(worstGltf < 1e-3, 'GLTFLoader: bodies within 1 mm of MuJoCo\'s positions', `worst ${(worstGltf * 1000).toFixed(3)} mm`);
    check(skinnedChecks > 0 && worstSkin < 1e-3, 'AnimationMixer: the SkinnedMesh\'s vertices within 1 mm of MuJoCo\'s bodies',
      `${skinnedChecks} vertices, worst ${(worstSkin * 1000).toFixed(3)} mm`);

    // all.glb in a small three.js viewer page, in Chromium.
    const here = dirname(fileURLToPath(import.meta.url));
    const { build } = await import('esbuild');
    const bundle = await build({ entryPoints: [join(here, 'gltf-view.js')], bundle: true, format: 'iife', write: false, logLevel: 'warning' });
    const glb = readFileSync(join(exportDir, 'all.glb')).toString('base64');
    const html = `<!doctype html><html><head><meta charset="utf-8"><title>all.glb</title></head>
<body style="margin:0"><canvas id="view" width="1200" height="700"></canvas>
<script type="text/plain" id="glb">${glb}</script>
<script>${bundle.outputFiles[0].text.replace(/<\/script/gi, '<\\/script')}</script></body></html>`;
    const viewer = join(runDir, 'gltf-view.html');
    writeFileSync(viewer, html);
    const vpage = await context.newPage();
    const viewErrors = [];
    vpage.on('pageerror', (e) => viewErrors.push(e.message));
    vpage.on('console', (m) => { if (m.type() === 'error') viewErrors.push(m.text()); });
    await vpage.goto(pathToFileURL(viewer).href);
    await vpage.waitForSelector('body[data-ready="1"]', { timeout: 30000 });
    const drawn = await vpage.evaluate(() => window.__gltfStats);
    check(drawn.meshes > 0 && drawn.colours > 100, 'all.glb draws in Chromium with three.js', JSON.stringify(drawn));
    check(viewErrors.length === 0, 'the glTF viewer logs no errors', viewErrors.join(' | '));
    await vpage.screenshot({ path: join(runDir, 'gltf-screenshot.png') });
  }
} finally {
  await context.close();
  rmSync(userDataDir, { recursive: true, force: true });
}

// ---------------------------------------------------------------- without WebGL

// A browser with WebGL turned off gets the page's message instead of the views, and still
// the header, the distance table with the robustness shares, and the plots.
const plainDir = mkdtempSync(join(tmpdir(), 'diverse-e2e-chromium-'));
const plain = await chromium.launchPersistentContext(plainDir, {
  executablePath,
  headless: true,
  viewport: { width: 1400, height: 1100 },
  args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-3d-apis', '--no-first-run',
    '--disable-background-networking', '--disable-component-update', '--disable-sync'],
});
try {
  const page = await plain.newPage();
  const pageErrors = [];
  page.on('pageerror', (e) => pageErrors.push(e.message));
  await page.goto(pathToFileURL(join(runDir, 'gallery.html')).href);
  await page.waitForSelector('#webgl-error:not([hidden])', { timeout: 30000 });
  const shown = await page.evaluate(() => {
    const data = JSON.parse(document.getElementById('gallery-data').textContent);
    return {
      task: data.task,
      motions: data.motions.length,
      robustness: Boolean(data.robustness),
      progress: (data.progress?.generation || []).length > 0,
      title: document.getElementById('title').textContent,
      distances: !document.getElementById('distance-panel').hidden,
      rows: document.querySelectorAll('#distances tr').length,
      robust: [...document.querySelectorAll('#distances td.robust')].map((t) => t.textContent),
      plotD: document.querySelectorAll('#plot-d svg').length,
      heatmaps: document.querySelectorAll('#heatmaps .heatmap-box').length,
      stageHidden: document.getElementById('stage').hidden,
      transportHidden: document.getElementById('transport').hidden,
    };
  });
  check(shown.stageHidden && shown.transportHidden, 'without WebGL: the page says so and hides the views and their playback');
  check(shown.title === shown.task, 'without WebGL: the header names the task', shown.title);
  check(!shown.distances || shown.rows === shown.motions + 1, 'without WebGL: the distance table has a row per motion',
    `${shown.rows} rows`);
  check(!shown.robustness || shown.robust.length === shown.motions,
    'without WebGL: every motion\'s robustness share is in the table', shown.robust.join(', '));
  check(!shown.progress || shown.plotD === 1, 'without WebGL: the plots are drawn', `${shown.plotD} D plots`);
  check(!shown.distances || shown.heatmaps > 0, 'without WebGL: the distance heatmaps are drawn', `${shown.heatmaps}`);
  check(pageErrors.length === 1, 'without WebGL: the one error is the failed WebGL context', pageErrors.join(' | '));
} finally {
  await plain.close();
  rmSync(plainDir, { recursive: true, force: true });
}

console.log(`gallery e2e: ${passed} passed, ${failed} failed`);
process.exit(failed === 0 ? 0 : 1);
