// stereobench report: renders the sweep data embedded in index.html (script#report-data, schema
// "stereobench.report 1", docs/report.md) into summary tables, charts, the paper's experiment
// beside ours, and one image viewer per cell. Runs offline from file://; Chart.js draws the charts.
'use strict';

(function () {
  const data = JSON.parse(document.getElementById('report-data').textContent);
  const pipelines = data.pipelines;
  const cells = data.cells;

  // ---------------------------------------------------------------- DOM and number helpers

  /** Creates an element: attrs sets attributes (or properties for on* handlers), children are nodes or text. */
  function el(tag, attrs, ...children) {
    const node = document.createElement(tag);
    for (const [key, value] of Object.entries(attrs || {})) {
      if (value === null || value === undefined || value === false) continue;
      if (key.startsWith('on')) node.addEventListener(key.slice(2), value);
      else if (key === 'text') node.textContent = value;
      else node.setAttribute(key, value === true ? '' : String(value));
    }
    for (const child of children.flat(Infinity)) {
      if (child === null || child === undefined) continue;
      node.append(child instanceof Node ? child : document.createTextNode(String(child)));
    }
    return node;
  }

  /** A metric value as a number: "inf" is Infinity, null/missing is null. */
  function num(v) {
    if (v === 'inf') return Infinity;
    if (v === '-inf') return -Infinity;
    return typeof v === 'number' && !Number.isNaN(v) ? v : null;
  }

  /** A value for a table: — for a missing value, ∞ for an infinite one. */
  function fmt(v, digits, scale) {
    const n = num(v);
    if (n === null) return '—';
    if (n === Infinity) return '∞';
    if (n === -Infinity) return '−∞';
    return (n * (scale || 1)).toFixed(digits);
  }

  /** Median of the numeric values (nulls ignored, ∞ sorts last); null when there is none. Of two
   * middle values one infinite, the finite one: a PSNR of ∞ (identical images) beside a finite
   * one would otherwise make the median ∞, identical to the truth. */
  function median(values) {
    const xs = values.map(num).filter((x) => x !== null).sort((a, b) => a - b);
    if (xs.length === 0) return null;
    const m = xs.length >> 1;
    if (xs.length % 2 === 1 || xs[m - 1] === xs[m]) return xs[m];
    const [a, b] = [xs[m - 1], xs[m]];
    if (Number.isFinite(a) !== Number.isFinite(b)) return Number.isFinite(a) ? a : b;
    return (a + b) / 2;
  }

  function minOf(values) {
    const xs = values.map(num).filter((x) => x !== null);
    return xs.length ? Math.min(...xs) : null;
  }

  function maxOf(values) {
    const xs = values.map(num).filter((x) => x !== null);
    return xs.length ? Math.max(...xs) : null;
  }

  /** Distinct values in order of first appearance. */
  function distinct(values) {
    return [...new Set(values)];
  }

  /** A relative path as a URL: each segment percent-encoded. */
  function urlOf(path) {
    return path.split('/').map((s) => (s === '..' || s === '.' ? s : encodeURIComponent(s))).join('/');
  }

  // Fourteen colours of distinct hue or lightness, eight markers and four dash patterns. Style k
  // takes colour k mod 14, marker k mod 8 and dash floor(k / 7) mod 4: of the first 56 styles, any
  // two with the same marker and dash have colours at least 80 apart in RGB.
  const palette = ['#1f5fbf', '#d9480f', '#2b8a3e', '#862e9c', '#c92a2a', '#0b7285', '#f08c00', '#74b816',
    '#212529', '#e64980', '#22b8cf', '#868e96', '#8d5524', '#7048e8'];
  const dashes = [[], [8, 4], [2, 3], [10, 3, 2, 3]];
  const markers = ['circle', 'triangle', 'rect', 'rectRot', 'star', 'crossRot', 'rectRounded', 'cross'];
  /** Line style k: its colour, marker and dash pattern. */
  function lineStyle(k) {
    const i = k < 0 ? 0 : k;
    return { color: palette[i % palette.length], marker: markers[i % markers.length],
      dash: dashes[Math.floor(i / 7) % dashes.length] };
  }
  /** Distinct colours for the stages of the stacked bars: hues spread by the golden angle, and
   * three lightness levels and two saturations, so that stages whose hues come close (i and i + 8,
   * i + 13, i + 21 apart) differ in lightness or saturation. */
  function stageColor(i) {
    return `hsl(${Math.round((i * 137.508 + 210) % 360)}, ${Math.floor(i / 12) % 2 ? 45 : 75}%, ${[40, 54, 68][i % 3]}%)`;
  }

  /**
   * Chart.js's legend below a chart takes at most half of the canvas and drops what does not fit,
   * without a word. The legend here takes what it needs, and this plugin grows or shrinks the
   * chart's box so that the plot area keeps `plot` pixels of height, whatever the number of
   * entries and the width of the page.
   */
  function keepPlotHeight(plot) {
    return { id: 'keepPlotHeight', afterLayout(chart) {
      const box = chart.canvas.parentNode;
      const area = chart.chartArea;
      if (!box || !area) return;
      const want = Math.round(box.clientHeight + plot - (area.bottom - area.top));
      if (Math.abs(want - box.clientHeight) > 2) box.style.height = `${want}px`;  // Chart.js follows its box
    } };
  }

  /** Why pipelines are missing from a chart: where the chart says why a value is ∞
   * (`infiniteWhy`), those whose values are ∞ apart from those with no finite value otherwise
   * (missing, NaN); '' when none is missing. */
  function omittedNote(infinite, missing, infiniteWhy) {
    const parts = [];
    if (infinite.length && infiniteWhy) parts.push(`${infiniteWhy}: ${infinite.join(', ')}`);
    const plain = infiniteWhy ? missing : [...infinite, ...missing];
    if (plain.length) parts.push(`no finite value: ${plain.join(', ')}`);
    return parts.length ? ` Not plotted (${parts.join('; ')}).` : '';
  }

  /**
   * The line of pipeline `label` in a chart: its style, and markers whose radius suits `along`
   * points per line (markers on every point of a long series merge into bands: smaller, then none;
   * the line and the tooltips remain). A line with one finite value has no line to show it: its
   * marker stays.
   */
  function lineDataset(label, data, style, along) {
    const finite = data.filter((v) => v !== null && (typeof v !== 'object' || v.y !== null)).length;
    return { label, data, borderColor: style.color, backgroundColor: style.color, pointStyle: style.marker,
      pointRadius: finite < 2 || along <= 30 ? 5 : along <= 120 ? 2 : 0, pointHitRadius: 6, borderWidth: 2,
      borderDash: style.dash, spanGaps: true, clip: 8 };
  }

  /** The legend of the line charts: below the plot, the first pipelines first (their lines are
   * drawn last, on top), as tall as it needs (keepPlotHeight keeps the plot's height). */
  const lineLegend = { position: 'bottom', reverse: true, maxHeight: 100000, labels: { usePointStyle: true } };

  /** Metres as given, to nine significant digits (0.501 m is not 0.50 m). */
  function metres(v) {
    const n = num(v);
    return n === null || !Number.isFinite(n) ? fmt(v, 2) : String(Number(n.toPrecision(9)));
  }

  function resolutionLabel(c) {
    return `${c.width}×${c.height}`;
  }

  function interaxialMm(c) {
    return Math.round(c.interaxial_m * 1e6) / 1e3;
  }

  /**
   * The sweep's interaxial axis as it was given: the maximum disparity in pixels (Al-Hagri's e),
   * whose metres change with the resolution, or the interaxial in millimetres.
   */
  const disparityAxis = cells.length > 0 && cells.every((c) => typeof c.axis_max_disparity_px === 'number');
  const interaxialKey = disparityAxis ? (c) => c.axis_max_disparity_px : interaxialMm;
  const interaxialUnit = disparityAxis ? 'px' : 'mm';
  const interaxialTitle = disparityAxis ? 'interaxial e (max disparity, px)' : 'interaxial e (mm)';

  function lightsLabel(c) {
    return c.lights === null || c.lights === undefined ? 'all' : String(c.lights);
  }

  /** A one-line description of a cell's axes. */
  function cellLabel(c) {
    const parts = [axisDefs.scene(c), resolutionLabel(c), `e = ${interaxialMm(c)} mm (${fmt(c.max_disparity_px, 1)} px)`,
      `c = ${metres(c.convergence_m)} m`, `lights ${lightsLabel(c)}`, `truth ${c.truth}`];
    if (c.path !== null && c.path !== undefined) parts.push(`path ${c.path}`);
    if (c.frame !== null && c.frame !== undefined) parts.push(`frame ${c.frame}`);
    return parts.join(' · ');
  }

  /** A short name of a cell: its number, scene and resolution, and every other axis that varies. */
  function cellShort(c, i) {
    const varying = ['interaxial', 'convergence', 'lights', 'truth', 'path', 'frame']
      .filter((a) => distinct(cells.map(axisDefs[a])).length > 1).map((a) => axisDefs[a](c));
    return [`${i + 1}. ${axisDefs.scene(c)} ${resolutionLabel(c)}`, ...varying].join(', ');
  }

  function cellAnchor(i) {
    return `cell-${String(i).padStart(4, '0')}`;
  }

  /** A pipeline's record in a cell, or null when the cell did not run it. */
  function rec(c, p) {
    return c.pipelines[p] || null;
  }

  function field(c, p, key) {
    const r = rec(c, p);
    return r ? r[key] : null;
  }

  /** Table from a header row and body rows of cells {text, num, cls, rowspan, th}. */
  function table(captionText, header, rows, opts) {
    const thead = el('thead', {}, el('tr', {}, header.map((h) => el('th', {
      scope: 'col', class: h.cls || null, title: h.title || null,
    }, h.text))));
    const tbody = el('tbody');
    for (const row of rows) {
      const tr = el('tr', { class: row.cls || null });
      for (const c of row.cells) {
        const tag = c.th ? 'th' : 'td';
        const cls = [c.num ? 'num' : null, c.cls || null].filter(Boolean).join(' ') || null;
        tr.append(el(tag, { class: cls, rowspan: c.rowspan || null, scope: c.th ? 'row' : null, title: c.title || null },
          c.node || c.text));
      }
      tbody.append(tr);
    }
    const t = el('table', { class: (opts && opts.cls) || null }, el('caption', {}, captionText), thead, tbody);
    return el('div', { class: 'table-wrap' }, t);
  }

  // ---------------------------------------------------------------- charts

  if (window.Chart) {
    Chart.defaults.animation = false;
    Chart.defaults.font.family = '"DejaVu Sans", system-ui, sans-serif';
    Chart.defaults.color = '#1d2430';
    Chart.defaults.maintainAspectRatio = false;
  }
  const pendingCharts = [];

  /** A figure with a canvas; the chart is drawn once the figure is in the document. */
  /** `height`: of the chart box in px (plot and legend); `wide`: the figure spans the grid's width. */
  function chartFigure(title, caption, config, height, wide) {
    const canvas = el('canvas', { role: 'img', 'aria-label': `${title}. ${caption}` });
    const fig = el('figure', { class: wide ? 'chart wide' : 'chart' }, el('figcaption', {}, title),
      el('div', { class: 'chart-box', style: `height: ${Math.round(height)}px` }, canvas), el('p', { class: 'caption' }, caption));
    pendingCharts.push(() => {
      if (!window.Chart) {
        fig.append(el('p', { class: 'warning' }, 'Chart.js did not load (assets/chart.umd.min.js); the numbers are in the tables.'));
        return;
      }
      canvas.chart = new Chart(canvas, config);
      canvas.chart.resize();  // to the box keepPlotHeight set in the first layout, at once
    });
    return fig;
  }

  function axis(title, extra) {
    return Object.assign({ title: { display: true, text: title } }, extra || {});
  }

  /** The sweep's axes, each as a label of a cell's value. */
  const axisDefs = {
    scene: (c) => c.scene + (Object.keys(c.scene_params || {}).length ? ` ${JSON.stringify(c.scene_params)}` : ''),
    resolution: resolutionLabel,
    interaxial: (c) => `e = ${interaxialKey(c)} ${interaxialUnit}`,
    convergence: (c) => `c = ${metres(c.convergence_m)} m`,
    lights: (c) => `lights ${lightsLabel(c)}`,
    truth: (c) => `truth ${c.truth}`,
    path: (c) => (c.path === null || c.path === undefined ? '' : `path ${c.path}`),
    frame: (c) => (typeof c.frame === 'number' ? `frame ${c.frame}` : ''),
  };

  /**
   * The cells grouped by the values of every axis but `plotted` that varies in the sweep, largest
   * group first: a chart against one axis shows one such group at a time, as the papers vary one
   * axis with the others fixed. One group labelled '' when no other axis varies.
   */
  function contextGroups(plotted, among) {
    const varying = Object.keys(axisDefs).filter((a) => a !== plotted && distinct(among.map(axisDefs[a])).length > 1);
    const label = (c) => varying.map((a) => axisDefs[a](c)).join(', ');
    const groups = distinct(among.map(label)).map((l) => ({ label: l, cells: among.filter((c) => label(c) === l) }));
    return groups.sort((a, b) => b.cells.length - a.cells.length);
  }

  /**
   * Line chart of a per-pipeline value against one axis of the cells (opts.axis), the other axes
   * fixed (a selector switches between their combinations): each point the median over the cells
   * that share the value. Returns null when no pipeline has a finite value.
   */
  function metricVsAxis(opts) {
    const build = (group) => {
      const keys = distinct(group.map(opts.key)).sort((a, b) => opts.order(a) - opts.order(b));
      const datasets = [];
      const infinite = [];
      const missing = [];
      for (const p of opts.pipelines) {
        const points = keys.map((k) => {
          const m = median(group.filter((c) => opts.key(c) === k && rec(c, p)).map((c) => opts.value(c, p)));
          return m === null || !Number.isFinite(m) ? null : m;
        });
        if (points.every((v) => v === null)) {
          const ran = group.filter((c) => rec(c, p));
          if (ran.some((c) => Math.abs(num(opts.value(c, p))) === Infinity)) infinite.push(p);
          else if (ran.length) missing.push(p);
          continue;
        }
        // Pipelines with equal values (e.g. two exact ones) overlap: each has its own marker and
        // dash pattern, and the first pipelines are drawn last (on top, datasets are added in
        // reverse and the legend reversed back), so that both stay visible; clip keeps edge markers whole.
        datasets.unshift(lineDataset(p, opts.linear ? keys.map((key, i) => ({ x: opts.order(key), y: points[i] })) : points,
          lineStyle(pipelines.indexOf(p)), keys.length));
      }
      let why = omittedNote(infinite, missing, opts.omittedWhy);
      if (keys.length === 1) why += ` These cells share one value of the ${opts.axis}: one point per pipeline.`;
      return { data: { labels: opts.linear ? undefined : keys.map(opts.label), datasets }, why, count: group.length };
    };
    // Only the combinations where some pipeline has a finite value.
    const groups = contextGroups(opts.axis, opts.cells || cells).filter((g) => build(g.cells).data.datasets.length > 0);
    if (groups.length === 0) return null;
    const first = build(groups[0].cells);
    const scales = {
      x: opts.linear ? axis(opts.xTitle, Object.assign({ type: 'linear' }, opts.xExtra || {})) : axis(opts.xTitle, { offset: true }),
      y: axis(opts.yTitle, opts.yExtra || {}),
    };
    const config = { type: 'line', data: first.data, plugins: [keepPlotHeight(200)],
      options: { scales, plugins: { legend: lineLegend } } };
    const context = (g, b) => (g.label ? ` Shown: ${g.label} (${b.count} of ${cells.length} cells).` : '');
    // A first guess of the box: the plot and a legend row per five pipelines (keepPlotHeight
    // corrects it as laid out).
    const height = 230 + 24 * Math.ceil(opts.pipelines.length / 5);
    const fig = chartFigure(opts.title, opts.caption + context(groups[0], first) + first.why, config, height);
    if (groups.length > 1) {
      const id = `ctx-${++contextSelects}`;
      const select = el('select', { id }, groups.map((g, i) => el('option', { value: i }, `${g.label} (${g.cells.length} cell${g.cells.length === 1 ? '' : 's'})`)));
      select.addEventListener('change', () => {
        const g = groups[Number(select.value)];
        const b = build(g.cells);
        const chart = fig.querySelector('canvas').chart;
        chart.data = b.data;
        chart.update();
        fig.querySelector('p.caption').textContent = opts.caption + context(g, b) + b.why;
      });
      fig.insertBefore(el('div', { class: 'context' }, el('label', { for: id }, 'Other axes fixed at '), select), fig.querySelector('.chart-box'));
    }
    return fig;
  }
  let contextSelects = 0;

  // ---------------------------------------------------------------- stage groups (Kim Table 3)

  /** Rendering or warping, as `stereobench bench --preset kim-complexity` groups the stages. */
  function stageGroup(stage) {
    if (stage === 'redirect' || stage === 'ztest' || /_(gbuffer|shading|trace)$/.test(stage)) return 'rendering';
    const warping = ['motion', 'warp', 'warp_depth', 'warp_color', 'backward_warp', 'row_warp', 'reproject',
      'crack_fill', 'hole_fill', 'background'];
    return warping.includes(stage) ? 'warping' : 'other';
  }

  function groupSeconds(stages, group) {
    let sum = 0;
    let any = false;
    for (const [name, s] of Object.entries(stages || {})) {
      if (stageGroup(name) === group && typeof s === 'number') {
        sum += s;
        any = true;
      }
    }
    return any ? sum : null;
  }

  /** Speed-up of pipeline p over `base` in cell c: the sweep's paired median when base is the
   * sweep's baseline, else the ratio of the two median times. */
  function speedupOver(c, p, base) {
    if (!rec(c, p)) return null;
    if (base === c.baseline) return field(c, p, 'speedup');
    const tb = num(field(c, base, 'time_s'));
    const tp = num(field(c, p, 'time_s'));
    return tb !== null && tp !== null && tp > 0 ? tb / tp : null;
  }

  // ---------------------------------------------------------------- sections

  function overviewSection() {
    const truths = distinct(cells.map((c) => c.truth));
    const scenes = distinct(cells.map(axisDefs.scene));
    const resolutions = distinct(cells.map(resolutionLabel));
    const interaxials = distinct(cells.map(interaxialKey)).sort((a, b) => a - b);
    const v = data.versions || {};
    const rows = [
      ['Sweep', data.sweeps.join(', ') + (data.description ? ` — ${data.description}` : '')],
      ['Definition', data.definition ? `${data.definition}${data.definition_sha256 ? ' (sha256 ' + String(data.definition_sha256).slice(0, 12) + '…)' : ''}` : '—'],
      ['Results file', `${data.results_file} (${cells.length} cell${cells.length === 1 ? '' : 's'})`],
      ['Pipelines', pipelines.map((p) => (p === data.baseline ? `${p} (baseline)` : p)).join(', ')],
      ['Ground truth', truths.join(', ')],
      ['Scenes', scenes.join(', ')],
      ['Resolutions', resolutions.join(', ')],
      [disparityAxis ? 'Interaxial (max disparity)' : 'Interaxial', interaxials.map((e) => `${e} ${interaxialUnit}`).join(', ')],
      ['Machine', `${(data.hosts || []).join(', ') || '—'}; ${data.threads ?? '—'} threads, ${data.jobs ?? '—'} job(s)`],
      ['Run', `${data.started ? `${data.started} to ${data.finished || '—'}; ` : ''}cells' wall time ${fmt(data.cells_wall_s, 1)} s (summed over cells)`],
      ['Versions', Object.entries(v).map(([k, x]) => `${k} ${x}`).join('; ') || '—'],
    ];
    const node = el('section', { 'aria-labelledby': 'overview-h' }, el('h2', { id: 'overview-h' }, 'Overview'),
      el('dl', { class: 'meta' }, rows.map(([k, x]) => [el('dt', {}, k), el('dd', {}, x)])));
    if (data.warnings && data.warnings.length)
      node.append(el('ul', { class: 'warnings', 'aria-label': 'Warnings' }, data.warnings.map((w) => el('li', {}, w))));
    return { id: 'overview', title: 'Overview', node };
  }

  const metricColumns = [
    { text: 'PSNR dB', title: 'Peak signal-to-noise ratio on 8-bit sRGB; ∞ when identical to the truth', key: 'psnr', digits: 2 },
    { text: 'SSIM', title: 'Structural similarity (Wang et al. 2004), mean over RGB', key: 'ssim', digits: 4 },
    { text: 'MSE', title: 'Mean squared error over 0–255 RGB', key: 'mse', digits: 3 },
    { text: 'Error px %', title: 'Pixels whose largest channel difference exceeds the threshold', key: 'error_fraction', digits: 3, scale: 100 },
    { text: 'Holes %', title: 'Hole pixels before filling', key: 'hole_fraction', digits: 3, scale: 100 },
    { text: 'Recall', title: 'Share of true disocclusions not shown by reprojection', key: 'recall', digits: 4 },
    { text: 'Precision', title: 'Share of not-reprojected pixels that needed it', key: 'precision', digits: 4 },
    { text: 'Time ms', title: 'Median wall-clock time of the pipeline', key: 'time_s', digits: 2, scale: 1000 },
    { text: 'Speed-up', title: `Over ${data.baseline}, paired per repetition in the same cell`, key: 'speedup', digits: 2 },
    { text: 'Right / left %', title: 'Time of the stages that serve the right eye over those that serve the left (the sweep: median over repetitions of each repetition’s ratio); — where no stage serves the left eye alone', key: 'right_over_left', digits: 1, scale: 100 },
  ];

  /** A row per pipeline of `ps`: its name, how many cells `has` it in, and the median of each column over those. */
  function pipelineRows(ps, columns, has) {
    return ps.map((p) => {
      const own = cells.filter((c) => has(c, p));
      return { cells: [{ text: p, th: true }, { text: String(own.length), num: true },
        ...columns.map((m) => ({ text: fmt(median(own.map((c) => field(c, p, m.key))), m.digits, m.scale), num: true }))] };
    });
  }

  /** A row per cell and pipeline of `ps` that `has` it there: the cell (a link to its viewer, once
   * per cell), the pipeline, and each column's value. */
  function cellPipelineRows(ps, columns, has) {
    const rows = [];
    cells.forEach((c, i) => {
      const present = ps.filter((p) => has(c, p));
      present.forEach((p, j) => {
        const row = { cls: j === 0 ? 'group-start' : null, cells: [] };
        if (j === 0)
          row.cells.push({ th: true, rowspan: present.length, node: el('a', { href: `#${cellAnchor(i)}` }, cellShort(c, i)),
            title: cellLabel(c) });
        row.cells.push({ text: p });
        for (const m of columns) row.cells.push({ text: fmt(field(c, p, m.key), m.digits, m.scale), num: true });
        rows.push(row);
      });
    });
    return rows;
  }

  function summarySection() {
    const header = [{ text: 'Pipeline' }, { text: 'Cells' }, ...metricColumns];
    const rows = pipelineRows(pipelines, metricColumns, (c, p) => rec(c, p) !== null);
    const node = el('section', { 'aria-labelledby': 'summary-h' }, el('h2', { id: 'summary-h' }, 'Summary per pipeline'),
      table(`Medians over the cells of the sweep (${cells.length}). PSNR is ∞ where the right eye equals the ground truth; — marks a value the cell does not have.`,
        header, rows));
    return { id: 'summary', title: 'Summary', node };
  }

  function chartsSection() {
    const node = el('section', { 'aria-labelledby': 'charts-h' }, el('h2', { id: 'charts-h' }, 'Charts'));
    const grid = el('div', { class: 'charts' });
    const others = pipelines.filter((p) => p !== data.baseline);
    const byResolution = {
      axis: 'resolution', key: (c) => resolutionLabel(c), order: (k) => { const [w, h] = k.split('×').map(Number); return w * h; },
      label: (k) => k, xTitle: 'resolution (per eye)',
    };
    const byInteraxial = { axis: 'interaxial', key: interaxialKey, order: (k) => k, label: (k) => `${k}`, linear: true, xTitle: interaxialTitle };
    const disparities = cells.map((c) => c.max_disparity_px);
    const dispNote = `Maximum disparity (at infinity) ${fmt(minOf(disparities), 1)}–${fmt(maxOf(disparities), 1)} px.`;
    // A chart with no finite value in any cell (SSIM of images too small for its window, say) is
    // not drawn, and the page says which.
    const notDrawn = [];
    const lineChart = (opts) => {
      const chart = metricVsAxis(opts);
      if (!chart && opts.pipelines.length > 0) notDrawn.push(opts.title);  // none but the baseline: nothing to say
      return chart;
    };
    const charts = [
      lineChart(Object.assign({}, byResolution, { pipelines: others, title: 'Speed-up vs resolution',
        value: (c, p) => field(c, p, 'speedup'), yTitle: `speed-up over ${data.baseline}`, yExtra: { beginAtZero: true },
        caption: `Median speed-up over ${data.baseline} (measured side by side in each cell) by image size.` })),
      lineChart(Object.assign({}, byInteraxial, { pipelines, title: 'PSNR vs interaxial', value: (c, p) => field(c, p, 'psnr'),
        yTitle: 'PSNR (dB)', omittedWhy: 'identical to the truth, PSNR ∞',
        caption: `Median PSNR of the right eye against the ground truth. ${dispNote}` })),
      lineChart(Object.assign({}, byInteraxial, { pipelines, title: 'SSIM vs interaxial', value: (c, p) => field(c, p, 'ssim'),
        yTitle: 'SSIM', caption: `Median SSIM of the right eye against the ground truth. ${dispNote}` })),
      lineChart(Object.assign({}, byInteraxial, { pipelines, title: 'MSE vs interaxial', value: (c, p) => field(c, p, 'mse'),
        yTitle: 'MSE (0–255 RGB)', yExtra: { beginAtZero: true }, caption: `Median MSE of the right eye against the ground truth. ${dispNote}` })),
      lineChart(Object.assign({}, byInteraxial, { pipelines, title: 'Hole fraction vs interaxial',
        value: (c, p) => { const h = num(field(c, p, 'hole_fraction')); return h === null ? null : 100 * h; },
        yTitle: 'hole pixels (%)', yExtra: { beginAtZero: true }, caption: `Median share of the right eye's pixels left as holes before filling. ${dispNote}` })),
      stageChart(),
      frameChart(),
    ].filter(Boolean);
    if (notDrawn.length)
      node.append(el('p', { class: 'note' }, `Not drawn, as no cell has a finite value for them: ${notDrawn.join(', ')}.`));
    grid.append(...charts);
    node.append(grid);
    return { id: 'charts', title: 'Charts', node };
  }

  /** Stacked bars: each pipeline's stage times in one combination of the sweep's axes (a selector
   * switches; the first shown is the largest image). Frames of a path are pooled (median). */
  function stageChart() {
    const stages = [];
    for (const p of pipelines)
      for (const c of cells)
        for (const s of Object.keys(field(c, p, 'stages_s') || {})) if (!stages.includes(s)) stages.push(s);
    if (stages.length === 0) return null;
    const pixels = (g) => Math.max(...g.cells.map((c) => c.width * c.height));
    const groups = contextGroups('frame', cells).sort((a, b) => pixels(b) - pixels(a) || b.cells.length - a.cells.length);
    const build = (group) => {
      const shown = pipelines.filter((p) => group.some((c) => rec(c, p)));
      const datasets = stages.map((s, i) => ({
        label: s, backgroundColor: stageColor(i),
        data: shown.map((p) => { const m = median(group.map((c) => (field(c, p, 'stages_s') || {})[s] ?? null)); return m === null ? 0 : 1000 * m; }),
      })).filter((d) => d.data.some((v) => v > 0));
      return { labels: shown, datasets };
    };
    const caption = (g) => `Median time of each stage${g.label ? ` at ${g.label}` : ''} (${g.cells.length} cell${g.cells.length === 1 ? '' : 's'}); stages are the pipelines' own timers.`;
    const config = { type: 'bar', data: build(groups[0].cells),
      options: { indexAxis: 'y', scales: { x: axis('time (ms)', { stacked: true }), y: { stacked: true, ticks: { autoSkip: false } } },
        plugins: { legend: { position: 'bottom', maxHeight: 100000 } } },
      plugins: [keepPlotHeight(30 + 24 * pipelines.length)] };
    // A first guess: a 24-px bar per pipeline, the axis, and a legend row per six stages; the
    // figure spans the grid.
    const height = 70 + 24 * pipelines.length + 22 * Math.ceil(stages.length / 6);
    const fig = chartFigure('Per-stage time', caption(groups[0]), config, height, true);
    if (groups.length > 1) {
      const id = `ctx-${++contextSelects}`;
      const select = el('select', { id }, groups.map((g, i) => el('option', { value: i }, g.label)));
      select.addEventListener('change', () => {
        const g = groups[Number(select.value)];
        const chart = fig.querySelector('canvas').chart;
        chart.data = build(g.cells);
        chart.update();
        fig.querySelector('p.caption').textContent = caption(g);
      });
      fig.insertBefore(el('div', { class: 'context' }, el('label', { for: id }, 'Cell '), select), fig.querySelector('.chart-box'));
    }
    return fig;
  }

  /** Frame time along a camera path, when the sweep has a frame axis. */
  function frameChart() {
    const framed = cells.filter((c) => typeof c.frame === 'number');
    if (framed.length === 0) return null;
    return metricVsAxis({ axis: 'frame', cells: framed, pipelines, title: 'Frame time along the path', key: (c) => c.frame, order: (k) => (typeof k === 'number' ? k : -1),
      label: (k) => String(k), linear: true, xTitle: 'frame', yTitle: 'time (ms)',
      // Frames are whole numbers: no tick between two.
      xExtra: { ticks: { stepSize: 1, precision: 0 } },
      value: (c, p) => { const t = num(field(c, p, 'time_s')); return t === null ? null : 1000 * t; },
      caption: 'Median time per frame of each pipeline along the camera path.' });
  }

  const leftColumns = [
    { text: 'Left synthesized %', title: 'Share of the left eye\'s pixels the pipeline did not render for the left eye (warped in from the right eye, filled)', key: 'left_synthesized_fraction', digits: 2, scale: 100 },
    { text: 'Left PSNR dB', title: 'The whole left eye against plain-rt\'s ray-traced left eye, 8-bit sRGB', key: 'left_psnr', digits: 2 },
    { text: 'Left SSIM', title: 'Structural similarity of the left eye against plain-rt\'s left eye', key: 'left_ssim', digits: 4 },
    { text: 'Left MSE', title: 'Mean squared error of the left eye over 0–255 RGB', key: 'left_mse', digits: 3 },
  ];

  /** Whether a pipeline record measured its left eye (one synthesized in part, as bidir-warp's). */
  function hasLeftEye(r) {
    return !!r && r.left_synthesized_fraction !== null && r.left_synthesized_fraction !== undefined;
  }

  /** Pipelines that synthesize part of their left eye too (bidir-warp): the left eye measured. */
  function leftEyeSection() {
    const measured = (c, p) => hasLeftEye(rec(c, p));
    const own = pipelines.filter((p) => cells.some((c) => measured(c, p)));
    if (!own.length) return null;
    const summary = pipelineRows(own, leftColumns, measured);
    const rows = cellPipelineRows(own, leftColumns, measured);
    const node = el('section', { 'aria-labelledby': 'left-eyes-h' }, el('h2', { id: 'left-eyes-h' }, 'Left eyes synthesized in part'),
      el('p', { class: 'note' }, 'These pipelines render only part of the left eye themselves and warp the rest in from the right eye, so the left eye is measured too: against plain-rt\'s ray-traced left eye, whichever ground truth gave the right eye\'s. Every other pipeline renders its left eye whole.'),
      table(`Medians per pipeline over the cells that measured a left eye.`, [{ text: 'Pipeline' }, { text: 'Cells' }, ...leftColumns], summary),
      table('Every measured left eye. The cell link opens its image viewer.', [{ text: 'Cell' }, { text: 'Pipeline' }, ...leftColumns], rows));
    return { id: 'left-eyes', title: 'Left eyes', node };
  }

  function cellTableSection() {
    const header = [{ text: 'Cell' }, { text: 'Pipeline' }, ...metricColumns];
    const rows = cellPipelineRows(pipelines, metricColumns, (c, p) => rec(c, p) !== null);
    const node = el('section', { 'aria-labelledby': 'cells-h' }, el('h2', { id: 'cells-h' }, 'Cells × pipelines'),
      table('Every pipeline in every cell. The cell link opens its image viewer; hover it for the cell\'s axes.', header, rows));
    return { id: 'cells', title: 'Cells × pipelines', node };
  }

  // ---------------------------------------------------------------- paper experiments

  function paperSection() {
    const paper = data.paper;
    if (!paper) return null;
    const node = el('section', { 'aria-labelledby': 'paper-h' }, el('h2', { id: 'paper-h' }, 'Paper experiment: ' + paper.title),
      el('p', { class: 'note' }, `Source: ${paper.source}. Their conditions: ${paper.conditions}. Our numbers come from this sweep on this machine (CPU); compare trends and ratios, not absolute times.`));
    const build = { 'wissmann-table2': wissmann, 'kim-table2': kimQuality, 'kim-table3': kimComplexity, 'al-hagri': alHagri }[paper.experiment];
    if (build) build(paper, node);
    for (const n of paper.notes || []) node.append(el('p', { class: 'note' }, n));
    return { id: 'paper', title: 'Paper experiment', node };
  }

  /** "HD", "4K" or W×H: how Wißmann names a resolution. */
  function wissmannResolution(c) {
    if (c.height === 1080) return 'HD';
    if (c.height === 2160) return '4K';
    return resolutionLabel(c);
  }

  function wissmann(paper, node) {
    const ourScenes = distinct(cells.map((c) => c.scene));
    const resolutions = distinct([...paper.rows.map((r) => r.resolution), ...cells.map(wissmannResolution)]);
    const header = [{ text: 'Resolution' }, { text: 'Renderer' },
      ...paper.scenes.map((s) => ({ text: `Paper: ${s}`, cls: 'paper', title: 'total ms over 1000 frames · speed-up' })),
      ...ourScenes.map((s) => ({ text: `Ours: ${s}`, title: 'median ms per frame · speed-up' }))];
    const rows = [];
    for (const res of resolutions) {
      paper.renderers.forEach((r, j) => {
        const row = { cls: j === 0 ? 'group-start' : null, cells: [] };
        if (j === 0) row.cells.push({ th: true, text: res, rowspan: paper.renderers.length });
        row.cells.push({ text: r.paper_name + ` (${r.pipeline})` });
        for (const s of paper.scenes) {
          const p = paper.rows.find((x) => x.resolution === res && x.scene === s && x.renderer === r.pipeline);
          row.cells.push({ num: true, cls: 'paper', text: p ? `${p.total_ms.toLocaleString('en')} ms · ${p.speedup === null ? '—' : p.speedup.toFixed(2) + '×'}` : '—' });
        }
        for (const s of ourScenes) {
          const own = cells.filter((c) => c.scene === s && wissmannResolution(c) === res && rec(c, r.pipeline));
          const t = median(own.map((c) => field(c, r.pipeline, 'time_s')));
          const sp = r.pipeline === paper.baseline ? null : median(own.map((c) => speedupOver(c, r.pipeline, paper.baseline)));
          row.cells.push({ num: true, text: own.length ? `${fmt(t, 1, 1000)} ms · ${sp === null ? '—' : fmt(sp, 2) + '×'}` : '—' });
        }
        rows.push(row);
      });
    }
    node.append(table('Speed-up over Plain Stereo (plain-raster) by scene and resolution: the paper\'s Table 2 beside this sweep.', header, rows));
    const holes = cells.filter((c) => rec(c, 'repro-rt')).map((c) => field(c, 'repro-rt', 'hole_fraction'));
    if (holes.length)
      node.append(el('p', {}, `Ours: Repro RT ray-traced ${fmt(median(holes), 1, 100)} % of the right eye's pixels at the median cell, ${fmt(maxOf(holes), 1, 100)} % at most, over every scene (paper: 6 % on average, 11.5 % at most, in Bistro Interior along its path; ours counts every hole pixel, the occluding-edge band and the surfaces outside the left frustum included).`));
  }

  function kimQuality(paper, node) {
    const dfs = distinct([...paper.rows.map((r) => r.focal_distance_mm), ...cells.map((c) => Math.round(c.convergence_m * 1000))])
      .sort((a, b) => b - a);
    // A method the paper has no column for (ours_only) gets only our column.
    const header = [{ text: 'DF (mm)' }, ...paper.methods.flatMap((m) => [
      ...(m.ours_only ? [] : [{ text: `Paper: ${m.paper_name}`, cls: 'paper', title: 'SSIM / PSNR dB' }]),
      { text: `Ours: ${m.pipeline}`, title: (m.ours_only ? `${m.paper_name}, not in the paper's table: ` : '') + 'SSIM / PSNR dB (median over cells)' }])];
    const rows = dfs.map((df) => {
      const p = paper.rows.find((r) => r.focal_distance_mm === df);
      const own = cells.filter((c) => Math.round(c.convergence_m * 1000) === df);
      return { cells: [{ th: true, text: String(df) }, ...paper.methods.flatMap((m) => {
        const theirs = p && p[m.pipeline] ? `${p[m.pipeline].ssim.toFixed(3)} / ${p[m.pipeline].psnr.toFixed(1)}` : '—';
        const mine = own.filter((c) => rec(c, m.pipeline));
        const ours = mine.length ? `${fmt(median(mine.map((c) => field(c, m.pipeline, 'ssim'))), 3)} / ${fmt(median(mine.map((c) => field(c, m.pipeline, 'psnr'))), 1)}` : '—';
        return m.ours_only ? [{ num: true, text: ours }] : [{ num: true, cls: 'paper', text: theirs }, { num: true, text: ours }];
      })] };
    });
    const truths = distinct(cells.map((c) => c.truth)).join(', ');
    node.append(table(`SSIM / PSNR of the warped right eye by focal distance (our ground truth: ${truths}).`, header, rows));
  }

  function kimComplexity(paper, node) {
    // A scene generated for a paper row has about its triangle count (within 25 %): same row.
    const rowOf = (t) => { const r = paper.rows.find((x) => Math.abs(t / x.triangles - 1) <= 0.25); return r ? r.triangles : t; };
    const ours = distinct(cells.map((c) => c.triangles).filter((t) => typeof t === 'number'));
    const counts = distinct([...paper.rows.map((r) => r.triangles), ...ours.map(rowOf)]).sort((a, b) => a - b);
    const header = [{ text: 'Complexity' }, { text: 'Method' }, { text: 'Paper rendering', cls: 'paper' }, { text: 'Paper warping', cls: 'paper' },
      { text: 'Ours rendering' }, { text: 'Ours warping' }, { text: 'Ours total' }];
    const rows = [];
    for (const t of counts) {
      const p = paper.rows.find((r) => r.triangles === t);
      const own = cells.filter((c) => typeof c.triangles === 'number' && rowOf(c.triangles) === t);
      const ownCounts = distinct(own.map((c) => c.triangles)).filter((n) => n !== t).map((n) => n.toLocaleString('en'));
      const label = (p ? p.label : `${t.toLocaleString('en')} tri.`) + (ownCounts.length ? ` (ours: ${ownCounts.join(', ')} tri.)` : p ? '' : ' (ours)');
      paper.methods.forEach((m, j) => {
        const row = { cls: j === 0 ? 'group-start' : null, cells: [] };
        if (j === 0) row.cells.push({ th: true, rowspan: paper.methods.length, text: label });
        const theirs = p ? p[m.pipeline] : null;
        const mine = own.filter((c) => rec(c, m.pipeline));
        const rendering = median(mine.map((c) => groupSeconds(field(c, m.pipeline, 'stages_s'), 'rendering')));
        const warping = median(mine.map((c) => groupSeconds(field(c, m.pipeline, 'stages_s'), 'warping')));
        row.cells.push({ text: `${m.paper_name} (${m.pipeline})` },
          { num: true, cls: 'paper', text: theirs ? fmt(theirs.rendering_ms, 3) : '—' },
          { num: true, cls: 'paper', text: theirs ? fmt(theirs.warping_ms, 3) : '—' },
          { num: true, text: mine.length ? fmt(rendering, 3, 1000) : '—' },
          { num: true, text: mine.length ? fmt(warping, 3, 1000) : '—' },
          { num: true, text: mine.length ? fmt(median(mine.map((c) => field(c, m.pipeline, 'time_s'))), 3, 1000) : '—' });
        rows.push(row);
      });
    }
    node.append(table('Rendering and warping time (ms) by triangle count: the paper\'s Table 3 beside this sweep (medians over cells).', header, rows));
    const fw = paper.forward_warp;
    if (!fw) return;
    // Table 1 is at FHD; the warp works in image space, so every triangle count's cells count.
    const fhd = cells.filter((c) => c.width === 1920 && c.height === 1080);
    const over = fhd.length ? fhd : cells;
    const warpRows = fw.methods.map((m) => {
      const mine = over.filter((c) => rec(c, m.pipeline)).map((c) => {
        const stages = field(c, m.pipeline, 'stages_s') || {};
        const parts = m.stages.map((s) => num(stages[s]));
        return parts.some((x) => x === null) ? null : parts.reduce((a, b) => a + b, 0);
      });
      return { cells: [{ th: true, text: `${m.paper_name} (${m.pipeline})` }, { num: true, cls: 'paper', text: fmt(m.ms, 3) },
        { text: m.stages.join(' + ') }, { num: true, text: fmt(median(mine), 3, 1000) }, { num: true, text: String(mine.filter((x) => x !== null).length) }] };
    });
    node.append(el('p', { class: 'note' }, fw.note),
      table(`${fw.title}, beside this sweep (${fhd.length ? '1920×1080 cells' : 'all cells: the sweep has no 1920×1080 cell'}).`,
        [{ text: 'Method' }, { text: 'Paper ms', cls: 'paper' }, { text: 'Our stages' }, { text: 'Ours ms' }, { text: 'Cells' }], warpRows));
  }

  function alHagri(paper, node) {
    const base = paper.baseline;
    const header = [{ text: 'Ray tracer' }, { text: 'Paper testbed 1', cls: 'paper' }, { text: 'Paper testbed 2', cls: 'paper' },
      { text: 'Ours median' }, { text: 'Ours range' }];
    const range = (r) => (r ? `${r[0].toFixed(2)}–${r[1].toFixed(2)}×` : '—');
    const rows = paper.tracers.filter((t) => t.pipeline !== base).map((t) => {
      const s = paper.speedup_ranges.find((x) => x.pipeline === t.pipeline);
      const values = cells.map((c) => speedupOver(c, t.pipeline, base)).filter((v) => v !== null);
      return { cells: [{ th: true, text: `${t.paper_name} (${t.pipeline})` },
        { cls: 'paper', text: s ? (s.text || range(s.testbed1)) : '—' }, { cls: 'paper', text: s ? (s.text || range(s.testbed2)) : '—' },
        { num: true, text: values.length ? fmt(median(values), 2) + '×' : '—' },
        { num: true, text: values.length ? `${fmt(minOf(values), 2)}–${fmt(maxOf(values), 2)}×` : '—' }] };
    });
    node.append(table(`Speed-up over the naïve ray tracer (${base}), as in Figures 27 and 35 (their percentages written as ratios).`, header, rows));

    const tracers = paper.tracers.map((t) => t.pipeline).filter((p) => pipelines.includes(p));
    const axes = {
      resolution: { axis: 'resolution', key: resolutionLabel, order: (k) => { const [w, h] = k.split('×').map(Number); return w * h; }, label: (k) => k, xTitle: 'image dimensions' },
      interaxial: { axis: 'interaxial', key: interaxialKey, order: (k) => k, label: (k) => String(k), linear: true, xTitle: interaxialTitle },
      lights: { axis: 'lights', key: lightsLabel, order: (k) => (k === 'all' ? 1e9 : Number(k)), label: (k) => k, xTitle: 'lights' },
    };
    const grid = el('div', { class: 'charts' });
    for (const f of paper.figures) {
      const a = axes[f.axis];
      if (distinct(cells.map(a.key)).length < 2) {
        node.append(el('p', { class: 'note' }, `${f.figure} (${f.quantity} vs ${f.axis}): this sweep holds the ${f.axis} fixed. Paper: ${f.finding}`));
        continue;
      }
      const fps = f.quantity === 'frame rate';
      const chart = metricVsAxis(Object.assign({}, a, { pipelines: fps ? tracers : tracers.filter((p) => p !== base),
        title: `${f.figure}: ${f.quantity} vs ${f.axis} (ours)`,
        value: fps ? (c, p) => { const t = num(field(c, p, 'time_s')); return t ? 1 / t : null; } : (c, p) => field(c, p, 'mse'),
        yTitle: fps ? 'frames per second' : 'MSE (0–255 RGB)', caption: `Paper: ${f.finding}` }));
      if (chart) grid.append(chart);
    }
    node.append(grid);
  }

  // ---------------------------------------------------------------- image viewer

  const modes = [
    { id: 'sbs', label: 'Side by side' },
    { id: 'slider', label: 'Slider' },
    { id: 'flicker', label: 'Flicker' },
    { id: 'anaglyph', label: 'Anaglyph' },
    { id: 'holes', label: 'Hole overlay' },
    { id: 'diff', label: 'Difference' },
  ];

  /** An <img> for a path (null: a placeholder saying the results lack it). */
  function picture(path, alt) {
    if (!path) return el('div', { class: 'missing', role: 'img', 'aria-label': `${alt}: not available` }, `${alt}: not in the results`);
    return el('img', { src: urlOf(path), alt, decoding: 'async' });
  }

  function figure(path, alt, caption) {
    return el('figure', {}, picture(path, alt), el('figcaption', {}, caption));
  }

  /** Loads an image off-screen; resolves to the element (or null when it fails). */
  function loadImage(path) {
    return new Promise((resolve) => {
      if (!path) { resolve(null); return; }
      const img = new Image();
      img.onload = () => resolve(img);
      img.onerror = () => resolve(null);
      img.src = urlOf(path);
    });
  }

  /** Red-cyan anaglyph of two images composed with blend modes (works on file:// pages, whose
   * images may not be read back): red from the left eye, green and blue from the right eye. */
  function drawAnaglyph(canvas, left, right) {
    const w = left.naturalWidth;
    const h = left.naturalHeight;
    canvas.width = w;
    canvas.height = h;
    const ctx = canvas.getContext('2d');
    ctx.drawImage(left, 0, 0);
    ctx.globalCompositeOperation = 'multiply';
    ctx.fillStyle = '#ff0000';
    ctx.fillRect(0, 0, w, h);
    const cyan = document.createElement('canvas');
    cyan.width = w;
    cyan.height = h;
    const c2 = cyan.getContext('2d');
    c2.drawImage(right, 0, 0, w, h);
    c2.globalCompositeOperation = 'multiply';
    c2.fillStyle = '#00ffff';
    c2.fillRect(0, 0, w, h);
    ctx.globalCompositeOperation = 'lighter';
    ctx.drawImage(cyan, 0, 0);
    ctx.globalCompositeOperation = 'source-over';
    canvas.dataset.drawn = 'true';
  }

  /** One cell's viewer: mode buttons, pipeline selector, and the six views. */
  function Viewer(cell, index) {
    const present = pipelines.filter((p) => rec(cell, p));
    const id = cellAnchor(index);
    let mode = 'sbs';
    let pipeline = present.find((p) => p !== cell.baseline) || present[0];
    let flickerTimer = null;
    let split = 50;

    const select = el('select', { id: `${id}-pipeline`, onchange: () => { pipeline = select.value; render(); } },
      present.map((p) => el('option', { value: p, selected: p === pipeline }, p)));
    const buttons = modes.map((m) => el('button', { type: 'button', 'data-mode': m.id, 'aria-pressed': m.id === mode ? 'true' : 'false',
      'aria-controls': `${id}-views`, onclick: () => setMode(m.id) }, m.label));
    const metrics = el('span', { class: 'legend', 'aria-live': 'polite' });
    const views = el('div', { id: `${id}-views`, class: 'views' });
    const root = el('div', { class: 'viewer' },
      el('div', { class: 'viewer-controls' },
        el('span', {}, el('label', { for: `${id}-pipeline` }, 'Pipeline'), select),
        el('div', { class: 'modes', role: 'group', 'aria-label': 'View mode' }, buttons), metrics),
      views);

    function stopFlicker() {
      if (flickerTimer !== null) clearInterval(flickerTimer);
      flickerTimer = null;
    }

    function setMode(m) {
      mode = m;
      for (const b of buttons) b.setAttribute('aria-pressed', b.dataset.mode === m ? 'true' : 'false');
      for (const v of views.children) v.hidden = v.dataset.view !== m;
      stopFlicker();
      if (m === 'flicker') startFlicker();
    }

    function startFlicker() {
      const view = views.querySelector('[data-view="flicker"]');
      const img = view.querySelector('img');
      const caption = view.querySelector('figcaption');
      const imgs = rec(cell, pipeline).images;
      if (!img || !imgs.right || !cell.images.truth) return;
      let showTruth = false;
      flickerTimer = setInterval(() => {
        showTruth = !showTruth;
        img.src = urlOf(showTruth ? cell.images.truth : imgs.right);
        img.alt = showTruth ? 'Ground-truth right eye' : `Right eye by ${pipeline}`;
        caption.textContent = showTruth ? 'Now: ground truth' : `Now: ${pipeline}`;
      }, 700);
    }

    function sliderView(imgs) {
      if (!imgs.right || !cell.images.truth)
        return [figure(imgs.right, `Right eye by ${pipeline}`, 'The slider needs the right eye and the ground truth.')];
      const top = el('div', { class: 'top' }, el('img', { src: urlOf(imgs.right), alt: `Right eye by ${pipeline} (left of the divider)` }));
      const divider = el('div', { class: 'divider' });
      const box = el('div', { class: 'compare' }, el('img', { src: urlOf(cell.images.truth), alt: 'Ground-truth right eye (right of the divider)' }),
        top, divider, el('span', { class: 'tag left' }, pipeline), el('span', { class: 'tag right' }, 'truth'));
      const range = el('input', { type: 'range', min: 0, max: 100, step: 0.5, value: split, id: `${id}-split`, 'aria-label': 'Divider position (percent of the width)' });
      const apply = (v) => {
        split = Math.max(0, Math.min(100, v));
        top.style.clipPath = `inset(0 ${100 - split}% 0 0)`;
        divider.style.left = `calc(${split}% - 1px)`;
        range.value = String(split);
      };
      range.addEventListener('input', () => apply(Number(range.value)));
      const fromPointer = (e) => { const r = box.getBoundingClientRect(); apply(((e.clientX - r.left) / r.width) * 100); };
      box.addEventListener('pointerdown', (e) => { box.setPointerCapture(e.pointerId); fromPointer(e); });
      box.addEventListener('pointermove', (e) => { if (box.hasPointerCapture(e.pointerId)) fromPointer(e); });
      apply(split);
      return [box, el('div', { class: 'range-row' }, el('label', { for: range.id }, 'Divider'), range),
        el('p', { class: 'legend' }, `Left of the divider: ${pipeline}; right of it: the ground truth. Drag the image or use the slider.`)];
    }

    function holesView(imgs) {
      if (!imgs.holes) return [figure(null, 'Hole overlay', '')];
      const top = el('div', { class: 'top' }, el('img', { src: urlOf(imgs.holes), alt: `Hole mask of ${pipeline} over its right eye` }));
      const base = imgs.right ? el('img', { src: urlOf(imgs.right), alt: `Right eye by ${pipeline}` }) : el('div');
      const range = el('input', { type: 'range', min: 0, max: 100, value: 100, id: `${id}-holes-opacity`, 'aria-label': 'Overlay opacity (percent)' });
      range.addEventListener('input', () => { top.style.opacity = String(Number(range.value) / 100); });
      return [el('div', { class: 'stack' }, base, top),
        el('div', { class: 'range-row' }, el('label', { for: range.id }, 'Overlay opacity'), range),
        el('p', { class: 'legend' }, 'Hole mask against the true disocclusions:',
          el('span', { class: 'swatch', style: 'background:#00c000' }), 'found',
          el('span', { class: 'swatch', style: 'background:#e00000' }), 'missed',
          el('span', { class: 'swatch', style: 'background:#2040ff' }), 'flagged without need')];
    }

    function anaglyphView(imgs) {
      const canvas = el('canvas', { role: 'img', 'aria-label': `Red-cyan anaglyph: left eye and the right eye by ${pipeline}` });
      const note = el('figcaption', {}, 'Red-cyan anaglyph (red: left eye; cyan: right eye by the pipeline). Composing…');
      Promise.all([loadImage(imgs.left || cell.images.left), loadImage(imgs.right)]).then(([left, right]) => {
        if (!left || !right) { note.textContent = 'The anaglyph needs the left eye and the pipeline\'s right eye; the results lack one.'; return; }
        drawAnaglyph(canvas, left, right);
        note.textContent = `Red-cyan anaglyph (red: left eye; cyan: right eye by ${pipeline}).`;
      });
      return [el('figure', { class: 'single' }, canvas, note)];
    }

    function render() {
      stopFlicker();
      const r = rec(cell, pipeline);
      const imgs = r.images;
      const left = hasLeftEye(r)
        ? ` · left eye PSNR ${fmt(r.left_psnr, 2)} dB, SSIM ${fmt(r.left_ssim, 4)} (${fmt(r.left_synthesized_fraction, 1, 100)} % synthesized)` : '';
      metrics.textContent = `PSNR ${fmt(r.psnr, 2)} dB · SSIM ${fmt(r.ssim, 4)} · MSE ${fmt(r.mse, 3)} · holes ${fmt(r.hole_fraction, 2, 100)} % · ${fmt(r.time_s, 2, 1000)} ms · ${fmt(r.speedup, 2)}×${left}`;
      const content = {
        sbs: [el('div', { class: 'pair' },
          imgs.left ? figure(imgs.left, `Left eye by ${pipeline}`, `Left eye by ${pipeline} (${fmt(r.left_synthesized_fraction, 1, 100)} % synthesized)`)
            : figure(cell.images.left, 'Left eye', 'Left eye'),
          figure(imgs.right, `Right eye by ${pipeline}`, `Right eye by ${pipeline}`))],
        slider: sliderView(imgs),
        flicker: [el('figure', { class: 'single' }, picture(imgs.right, `Right eye by ${pipeline}`), el('figcaption', {}, `Now: ${pipeline}`)),
          el('p', { class: 'legend' }, 'Alternates between the pipeline\'s right eye and the ground truth every 0.7 s; differences blink.')],
        anaglyph: anaglyphView(imgs),
        holes: holesView(imgs),
        diff: [el('div', { class: 'pair' },
          figure(imgs.diff, `Difference heat map of ${pipeline}`, 'Difference: black 0, violet 1 code, red about 15, pale yellow 255 (largest channel, log scale)'),
          figure(imgs.ssim, `SSIM map of ${pipeline}`, 'SSIM map: white 1, dark low; grey border without a value')),
          ...(imgs.left ? [el('div', { class: 'pair' },
            figure(imgs.left_diff, `Left-eye difference heat map of ${pipeline}`, 'Left eye against plain-rt\'s ray-traced left eye, same scale'))] : [])],
      };
      views.replaceChildren(...modes.map((m) => el('div', { class: 'view', 'data-view': m.id, hidden: m.id !== mode }, content[m.id])));
      if (mode === 'flicker') startFlicker();
    }

    let active = false;
    return {
      root,
      /** Builds the views (and so loads the images) when the cell is opened. */
      activate() { if (!active) { active = true; render(); } },
      /** Drops the views (and so the decoded images) when the cell is closed: a nightly report has
       * hundreds of HD and 4K images, and only the open cells hold theirs. Mode, pipeline and
       * divider position stay for the next opening. */
      deactivate() { stopFlicker(); views.replaceChildren(); active = false; },
    };
  }

  function viewerSection() {
    const node = el('section', { 'aria-labelledby': 'viewer-h' }, el('h2', { id: 'viewer-h' }, 'Image viewer per cell'),
      el('p', { class: 'note' }, 'Open a cell to load its images. Modes: side by side (left | right eye), slider (pipeline against the ground truth), flicker, red-cyan anaglyph, hole overlay, and difference and SSIM maps.'));
    cells.forEach((c, i) => {
      const viewer = Viewer(c, i);
      const details = el('details', { class: 'cell', id: cellAnchor(i), 'data-cell': c.id },
        el('summary', {}, cellShort(c, i), el('span', { class: 'sub' }, cellLabel(c))), viewer.root);
      details.addEventListener('toggle', () => (details.open ? viewer.activate() : viewer.deactivate()));
      if (i === 0) details.open = true;
      node.append(details);
    });
    return { id: 'viewer', title: 'Image viewer', node };
  }

  /** A link to a cell's viewer (#cell-NNNN: the tables' cell links, or the page opened at one)
   * opens that cell, which loads its images, and shows it. */
  function openLinkedCell() {
    let id = '';
    try {
      id = decodeURIComponent(window.location.hash.slice(1));
    } catch (e) {
      return;  // a fragment that is no valid percent-encoding names no cell
    }
    const target = id ? document.getElementById(id) : null;
    if (!target || !target.matches('details.cell')) return;
    target.open = true;
    target.scrollIntoView();
  }
  window.addEventListener('hashchange', openLinkedCell);


  /** Trends across the nightly runs of a history file (data.history, docs/nightly.md): per pipeline
   * the median PSNR and median time of each run, and the gate's verdict counts per run. */
  function trendsSection() {
    const runs = data.history;
    if (!Array.isArray(runs)) return null;
    const node = el('section', { 'aria-labelledby': 'trends-h' }, el('h2', { id: 'trends-h' }, 'Trends'));
    if (data.history_note) node.append(el('p', { class: 'note' }, data.history_note));
    if (runs.length === 0) {
      // The runs of other sweeps are left out (the note above counts them).
      node.append(el('p', { class: 'note' }, 'The history file holds no run of this sweep yet.'));
      return { id: 'trends', title: 'Trends', node };
    }
    const labels = runs.map((r) => String(r.date).replace('T', ' ').replace('Z', ''));
    // The axis names each run by its date, or date and time where a day has several runs, unrotated
    // and thinned to what fits (the tooltips give the full time; a category tick's value is the
    // index of its run): full rotated date-times took half of a chart's height, and the plot
    // shrank to a strip once the history held a few dozen runs.
    const days = labels.map((l) => l.slice(0, 10));
    const oneADay = new Set(days).size === days.length;
    const tickLabel = (i) => (oneADay ? days[i] : labels[i].slice(0, 16));
    const runAxis = (extra) => axis('run (UTC)', Object.assign({ ticks: { maxRotation: 0, autoSkip: true, autoSkipPadding: 12,
      callback: (value) => tickLabel(value) } }, extra));
    // This report's pipelines first (their styles as elsewhere), then those only earlier runs had,
    // with the styles after this report's.
    const names = distinct([...pipelines, ...runs.flatMap((r) => Object.keys(r.pipelines || {}))])
      .filter((p) => runs.some((r) => (r.pipelines || {})[p]));
    const extra = names.filter((p) => !pipelines.includes(p));
    const styleOf = (p) => lineStyle(pipelines.includes(p) ? pipelines.indexOf(p) : pipelines.length + extra.indexOf(p));
    const runText = `${runs.length} run${runs.length === 1 ? '' : 's'} from ${labels[0]} to ${labels[labels.length - 1]} UTC`;

    const lineChart = (title, key, scale, yTitle, caption, omittedWhy) => {
      const datasets = [];
      const infinite = [];
      const missing = [];
      names.forEach((p) => {
        const values = runs.map((r) => num(((r.pipelines || {})[p] || {})[key]));
        const points = values.map((v) => (v === null || !Number.isFinite(v) ? null : v * scale));
        if (points.every((v) => v === null)) {
          (values.some((v) => Math.abs(v) === Infinity) ? infinite : missing).push(p);
          return;
        }
        datasets.unshift(lineDataset(p, points, styleOf(p), runs.length));
      });
      if (datasets.length === 0) return null;
      const why = omittedNote(infinite, missing, omittedWhy);
      const config = { type: 'line', data: { labels, datasets }, plugins: [keepPlotHeight(200)],
        options: { scales: { x: runAxis({ offset: true }), y: axis(yTitle) },
          plugins: { legend: lineLegend } } };
      return chartFigure(title, `${caption} ${runText}.${why}`, config, 230 + 24 * Math.ceil(names.length / 5));
    };

    const verdicts = [['fail', '#c92a2a'], ['warn', '#f08c00'], ['pass', '#2b8a3e'], ['skip', '#868e96']];
    const gateChart = chartFigure('Gate verdict per run',
      `Checks of the gate per verdict in each run; a run fails with any failed check, warns with warnings only, else passes (skipped checks do not count). ${runText}.`,
      { type: 'bar', data: { labels, datasets: verdicts.map(([v, c]) => ({ label: v, backgroundColor: c,
        data: runs.map((r) => num(((r.gate || {}).counts || {})[v]) || 0) })) },
      options: { scales: { x: runAxis({ stacked: true }), y: axis('checks', { stacked: true, beginAtZero: true }) },
        plugins: { legend: { position: 'bottom' } } } }, 280);

    const grid = el('div', { class: 'charts' });
    grid.append(...[
      lineChart('PSNR per run', 'psnr', 1, 'median PSNR (dB)', 'Median PSNR over each run\'s cells, per pipeline.',
        'identical to the truth, PSNR ∞'),
      lineChart('Median time per run', 'median_s', 1000, 'median time (ms)', 'Median over each run\'s cells of the pipeline\'s median time.'),
      gateChart,
    ].filter(Boolean));
    node.append(grid);

    const header = [{ text: 'Run (UTC)' }, { text: 'Host' }, { text: 'Revision' }, { text: 'Cells' }, { text: 'Verdict' },
      ...verdicts.map(([v]) => ({ text: v }))];
    const rows = runs.map((r, i) => ({ cls: `verdict-${r.gate.verdict}`, cells: [
      { text: labels[i], th: true, title: r.run_id }, { text: r.host }, { text: r.git_revision },
      { text: String(r.cells ?? '—'), num: true }, { text: r.gate.verdict },
      ...verdicts.map(([v]) => ({ text: String(r.gate.counts[v] ?? 0), num: true }))] }));
    node.append(table(`Nightly runs of the history file, oldest first (${runs.length}).`, header, rows));
    return { id: 'trends', title: 'Trends', node };
  }

  // ---------------------------------------------------------------- page

  // Sections in page order; each returns {id, title, node} or null when the data has nothing for it.
  const sections = [overviewSection, summarySection, paperSection, chartsSection, trendsSection, cellTableSection,
    leftEyeSection, viewerSection];
  const main = document.getElementById('main');
  const toc = el('ul');
  for (const make of sections) {
    const s = make();
    if (!s) continue;
    s.node.id = s.id;
    main.append(s.node);
    toc.append(el('li', {}, el('a', { href: `#${s.id}` }, s.title)));
  }
  document.getElementById('toc').append(toc);
  for (const draw of pendingCharts) draw();
  openLinkedCell();
  document.documentElement.dataset.reportReady = 'true';
})();
