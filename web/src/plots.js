// The plots panel of the gallery: how the run went and what it found, drawn as SVG from the
// run's own data (no network, no plotting library).
//
//   - D of the current set and of the best set so far, per generation (log.jsonl);
//   - every variation's constraint value C and its dmin, per generation;
//   - the pairwise distance matrix as a heatmap, one per metric (summary.json);
//   - for a run whose bodies varied, every motion's link-length scales.
const SVG = 'http://www.w3.org/2000/svg';

// One colour per motion: M0 grey, the variations in a qualitative palette.
const PALETTE = ['#7b8794', '#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b',
  '#e377c2', '#bcbd22', '#17becf', '#393b79', '#637939'];
export const motionColour = (i) => PALETTE[i % PALETTE.length];

function svg(tag, attrs = {}, text) {
  const e = document.createElementNS(SVG, tag);
  for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
  if (text !== undefined) e.textContent = text;
  return e;
}

export function fmt(x) {
  if (x === null || x === undefined || Number.isNaN(x)) return 'n/a';
  if (x === 0) return '0';
  const a = Math.abs(x);
  if (a >= 1e4 || a < 1e-2) return x.toExponential(1).replace('e+', 'e');
  return x.toPrecision(3);
}

// Round tick values covering [lo, hi].
function ticks(lo, hi, count = 5) {
  if (!(hi > lo)) return [lo];
  const raw = (hi - lo) / count;
  const mag = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * mag).find((s) => s >= raw);
  const out = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + 1e-9 * step; v += step) out.push(Number(v.toPrecision(12)));
  return out;
}

// A line chart. series: [{ name, colour, ys, dash }], one y per x; y values that are null
// leave a gap. `scale` 'log1p' draws log10(1 + y) (for constraint penalties that span 0
// and 1e5) with ticks labelled in y.
export function lineChart({ title, xLabel, yLabel, xs, series, scale = 'linear', width = 460, height = 230 }) {
  const m = { left: 58, right: 12, top: 44, bottom: 40 };
  const w = width - m.left - m.right;
  const h = height - m.top - m.bottom;
  const f = scale === 'log1p' ? (y) => Math.log10(1 + Math.max(0, y)) : (y) => y;
  const values = series.flatMap((s) => s.ys.filter((y) => y !== null && Number.isFinite(y)).map(f));
  let lo = Math.min(0, ...values);
  let hi = Math.max(...values, lo + 1e-9);
  if (scale === 'linear' && lo >= 0) hi *= 1.05;
  if (!(hi - lo > 1e-6)) hi = lo + 1;
  const x0 = xs[0];
  const x1 = xs[xs.length - 1] > x0 ? xs[xs.length - 1] : x0 + 1;
  const X = (x) => m.left + ((x - x0) / (x1 - x0)) * w;
  const Y = (y) => m.top + h - ((f(y) - lo) / (hi - lo)) * h;
  const Yraw = (v) => m.top + h - ((v - lo) / (hi - lo)) * h;
  const root = svg('svg', { viewBox: `0 0 ${width} ${height}`, width, height, class: 'chart', role: 'img', 'aria-label': title });
  root.append(svg('text', { x: m.left, y: 16, class: 'chart-title' }, title));
  // Axes and grid.
  for (const t of ticks(x0, x1, 6).filter(Number.isInteger)) {  // generations are whole
    root.append(svg('line', { x1: X(t), x2: X(t), y1: m.top, y2: m.top + h, class: 'grid' }));
    root.append(svg('text', { x: X(t), y: m.top + h + 15, class: 'tick', 'text-anchor': 'middle' }, String(t)));
  }
  const yTicks = scale === 'log1p'
    ? [0, 1, 10, 100, 1e3, 1e4, 1e5, 1e6, 1e7].filter((v) => f(v) <= hi + 1e-9)
    : ticks(lo, hi, 5);
  for (const t of yTicks) {
    const y = scale === 'log1p' ? Y(t) : Yraw(t);
    root.append(svg('line', { x1: m.left, x2: m.left + w, y1: y, y2: y, class: 'grid' }));
    root.append(svg('text', { x: m.left - 6, y: y + 4, class: 'tick', 'text-anchor': 'end' }, fmt(t)));
  }
  root.append(svg('rect', { x: m.left, y: m.top, width: w, height: h, class: 'frame' }));
  root.append(svg('text', { x: m.left + w / 2, y: height - 6, class: 'axis', 'text-anchor': 'middle' }, xLabel));
  root.append(svg('text', { x: 12, y: m.top + h / 2, class: 'axis', 'text-anchor': 'middle', transform: `rotate(-90 12 ${m.top + h / 2})` }, yLabel));
  // Lines.
  for (const s of series) {
    let d = '';
    let pen = false;
    s.ys.forEach((y, k) => {
      if (y === null || !Number.isFinite(y)) { pen = false; return; }
      d += `${pen ? 'L' : 'M'}${X(xs[k]).toFixed(1)},${Y(y).toFixed(1)}`;
      pen = true;
    });
    const path = svg('path', { d, class: 'series', stroke: s.colour, 'data-series': s.name, 'data-points': s.ys.length });
    if (s.dash) path.setAttribute('stroke-dasharray', s.dash);
    path.append(svg('title', {}, s.name));
    root.append(path);
  }
  // Legend: a line under the title, left to right.
  let lx = m.left;
  for (const s of series) {
    root.append(svg('line', { x1: lx, x2: lx + 16, y1: 30, y2: 30, stroke: s.colour, 'stroke-width': 2.5, 'stroke-dasharray': s.dash || '' }));
    root.append(svg('text', { x: lx + 20, y: 34, class: 'legend' }, s.name));
    lx += 20 + 6.5 * s.name.length + 16;
  }
  return root;
}

// Sequential colour scale from pale to dark blue (0 .. 1).
function heat(t) {
  const a = [247, 251, 255];
  const b = [8, 48, 107];
  const c = a.map((v, i) => Math.round(v + (b[i] - v) * Math.min(1, Math.max(0, t))));
  return `rgb(${c[0]},${c[1]},${c[2]})`;
}

// A heatmap of one metric's distance matrix, labels M0..MN, each cell's value written in it.
export function heatmap({ title, labels, matrix, optimized }) {
  const n = labels.length;
  const cell = Math.max(30, Math.min(54, Math.floor(250 / Math.max(n, 1))));
  const m = { left: 34, top: 40 };
  const size = m.left + n * cell + 8;
  const root = svg('svg', { viewBox: `0 0 ${size} ${m.top + n * cell + 8}`, width: size, height: m.top + n * cell + 8, class: 'heatmap', role: 'img', 'aria-label': title });
  root.append(svg('text', { x: m.left, y: 15, class: 'chart-title' }, title + (optimized ? ' (optimized)' : '')));
  let max = 0;
  for (let i = 0; i < n; ++i) for (let j = 0; j < n; ++j) if (i !== j) max = Math.max(max, matrix[i]?.[j] ?? 0);
  for (let i = 0; i < n; ++i) {
    root.append(svg('text', { x: m.left - 5, y: m.top + i * cell + cell / 2 + 4, class: 'tick', 'text-anchor': 'end' }, labels[i]));
    root.append(svg('text', { x: m.left + i * cell + cell / 2, y: m.top - 5, class: 'tick', 'text-anchor': 'middle' }, labels[i]));
    for (let j = 0; j < n; ++j) {
      const v = matrix[i]?.[j] ?? 0;
      const t = max > 0 ? v / max : 0;
      const rect = svg('rect', { x: m.left + j * cell, y: m.top + i * cell, width: cell - 1, height: cell - 1, fill: i === j ? '#eef0f3' : heat(t), class: 'cell' });
      rect.append(svg('title', {}, `d(${labels[i]}, ${labels[j]}) = ${fmt(v)}`));
      root.append(rect);
      if (i !== j) {
        root.append(svg('text', { x: m.left + j * cell + cell / 2, y: m.top + i * cell + cell / 2 + 4, class: 'cell-value', 'text-anchor': 'middle', fill: t > 0.55 ? '#fff' : '#1d232b' }, fmt(v)));
      }
    }
  }
  return root;
}

// Grouped bars: for each shape parameter, one bar per motion (its scale), with the line at 1.
export function shapeBars({ names, scales, labels, width = 940, height = 260 }) {
  const m = { left: 48, right: 10, top: 28, bottom: 64 };
  const w = width - m.left - m.right;
  const h = height - m.top - m.bottom;
  const hi = Math.max(2.5, ...scales.flat());
  const Y = (v) => m.top + h - (v / hi) * h;
  const root = svg('svg', { viewBox: `0 0 ${width} ${height}`, width, height, class: 'chart', role: 'img', 'aria-label': 'link-length scales' });
  root.append(svg('text', { x: m.left, y: 16, class: 'chart-title' }, 'Link-length scales of each motion (1 = the character as built)'));
  for (const t of ticks(0, hi, 5)) {
    root.append(svg('line', { x1: m.left, x2: m.left + w, y1: Y(t), y2: Y(t), class: 'grid' }));
    root.append(svg('text', { x: m.left - 6, y: Y(t) + 4, class: 'tick', 'text-anchor': 'end' }, String(t)));
  }
  const group = w / names.length;
  const bar = Math.max(2, (group - 8) / labels.length);
  names.forEach((name, p) => {
    labels.forEach((label, i) => {
      const v = scales[i]?.[p] ?? 1;
      const r = svg('rect', { x: m.left + p * group + 4 + i * bar, y: Y(v), width: bar - 1, height: Y(0) - Y(v), fill: motionColour(i), class: 'bar', 'data-motion': label });
      r.append(svg('title', {}, `${label} ${name}: ${v.toFixed(3)}`));
      root.append(r);
    });
    root.append(svg('text', { x: m.left + (p + 0.5) * group, y: m.top + h + 14, class: 'tick', 'text-anchor': 'end', transform: `rotate(-30 ${m.left + (p + 0.5) * group} ${m.top + h + 14})` }, name.replace(/^shape\./, '')));
  });
  root.append(svg('line', { x1: m.left, x2: m.left + w, y1: Y(1), y2: Y(1), class: 'unit' }));
  root.append(svg('rect', { x: m.left, y: m.top, width: w, height: h, class: 'frame' }));
  let lx = m.left;
  labels.forEach((label, i) => {
    root.append(svg('rect', { x: lx, y: height - 14, width: 10, height: 10, fill: motionColour(i) }));
    root.append(svg('text', { x: lx + 14, y: height - 5, class: 'legend' }, label));
    lx += 54;
  });
  return root;
}

// Fills the panel from the gallery's data (see src/render/gallery.h).
export function fillPlots(data, $) {
  const labels = data.motions.map((m) => m.label);
  const p = data.progress || {};
  const xs = p.generation || [];
  if (xs.length > 0) {
    $('plot-d').append(lineChart({
      title: 'Diversity D per generation', xLabel: 'generation', yLabel: 'D', xs,
      series: [
        { name: 'current set', colour: '#1f77b4', ys: p.D },
        { name: 'best set', colour: '#d62728', ys: p.best_D, dash: '5 3' },
      ],
    }));
    const perMotion = (key) => labels.map((label, i) => ({
      name: label, colour: motionColour(i), ys: p[key].map((row) => (i < row.length ? row[i] : null)),
    })).filter((s) => s.name !== 'M0' || key === 'dmin');
    $('plot-c').append(lineChart({
      title: 'Constraint value C of each variation', xLabel: 'generation', yLabel: 'C (0 = meets the task)', xs,
      series: perMotion('constraint'), scale: 'log1p',
    }));
    $('plot-dmin').append(lineChart({
      title: 'dmin: distance to the nearest other motion', xLabel: 'generation', yLabel: `dmin (${(data.metric || '').toUpperCase()})`, xs,
      series: perMotion('dmin'),
    }));
    const thinned = p.generations_total > xs.length ? `; ${xs.length} of ${p.generations_total} generations shown, evenly spaced` : '';
    $('progress-hint').textContent =
      `Where the set stood after each generation (log.jsonl)${thinned}. C is drawn on a log scale, log10(1 + C).`;
  } else {
    $('progress-panel').hidden = true;
  }

  const dist = data.distances || {};
  const combined = typeof dist.objective === 'string' && dist.objective.endsWith('+shape') ? [dist.objective] : [];
  const metrics = ['hf', 'md', 'wja', 'shape', ...combined].filter(
    (k) => Array.isArray(dist[k]) && (k !== 'shape' || dist[k].some((row) => row.some((v) => v > 0))));
  for (const k of metrics) {
    const box = document.createElement('div');
    box.className = 'heatmap-box';
    box.dataset.metric = k;
    box.append(heatmap({ title: k.toUpperCase(), labels, matrix: dist[k], optimized: k === dist.objective }));
    $('heatmaps').append(box);
  }
  if (!metrics.length) $('heatmap-panel').hidden = true;

  if (data.shape && data.shape.names?.length) {
    $('shape-panel').hidden = false;
    $('plot-shape').append(shapeBars({ names: data.shape.names, scales: data.shape.scales, labels }));
  }
}
