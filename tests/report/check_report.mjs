// Checks a `stereobench report` page in headless Debian Chromium, opened from disk (file://):
// no console error, page error, failed request or network request; one summary row per pipeline
// and one cell-table row per (cell, pipeline); a left-eyes row per measured left eye (bidir-warp's),
// with its PSNR; a cell link opens that cell's viewer; every chart canvas has data drawn inside its plot
// area; in every cell and for every pipeline each viewer image loads, each mode button shows its
// own view (all pipelines of the first cell, the first pipeline of the others), the slider follows
// a drag, flicker alternates, the anaglyph is composed exactly; with a history (nightly runs), the
// Trends section has a row per run and its charts a point per run; a full-page screenshot is written. Exit 0 when all holds, 1 with the list of problems otherwise.
//
// Usage: node tests/report/check_report.mjs REPORT/index.html SCREENSHOT.png [--quick]
// --quick leaves out the viewer's interaction (mode buttons, slider drag, flicker, the anaglyph's
// pixels) and keeps the rest: errors, tables, charts, every image of every cell and pipeline.
// Chromium: /usr/bin/chromium or $STEREOBENCH_CHROMIUM; playwright-core from ci/node_modules
// (ci/install-deps.sh chromium installs both).
import { createRequire } from 'node:module';
import { existsSync } from 'node:fs';
import { resolve } from 'node:path';
import { pathToFileURL } from 'node:url';

const args = process.argv.slice(2);
const quick = args.includes('--quick');
const [indexArg, screenshotArg] = args.filter((a) => a !== '--quick');
if (!indexArg || !screenshotArg) {
  console.error('usage: node tests/report/check_report.mjs REPORT/index.html SCREENSHOT.png [--quick]');
  process.exit(3);
}
const hint = 'install it with `ci/install-deps.sh chromium`';
const chromiumPath = process.env.STEREOBENCH_CHROMIUM || '/usr/bin/chromium';
if (!existsSync(chromiumPath)) {
  console.error(`check_report: ${chromiumPath} is missing; ${hint}`);
  process.exit(4);
}
const requireCi = createRequire(new URL('../../ci/package.json', import.meta.url));
let chromium;
try {
  ({ chromium } = requireCi('playwright-core'));
} catch (e) {
  console.error(`check_report: playwright-core is missing from ci/node_modules (${e.message}); ${hint}`);
  process.exit(4);
}

// A chart counts as drawn when its plot area holds at least this many saturated pixels (data
// lines, markers or bars; axes, grid and text are grey). Measured on the smoke sweep's report:
// 5,100-6,800 for the lines against interaxial, 660 for speed-up vs resolution (one marker per
// pipeline), 127,000 for the stacked bars; a chart of three single markers measured 127; an
// empty plot area has 0.
const MIN_CHART_DATA_PIXELS = 100;
// A chart of a few single markers may show fewer: markers whose values coincide are drawn on one
// another, and one on the edge of the plot area is cut in half (a nightly test's speed-up chart,
// three markers from one timing repetition, measured 74). Such a chart needs this many per
// distinct marker position Chart.js laid out, a third of one marker's 42 pixels, up to the
// minimum above.
const MIN_PIXELS_PER_POSITION = 14;
// Share of an anaglyph canvas's screenshot that is not black: the smoke sweep's anaglyphs measured
// 0.988-1.0 (box-wall's 0.987, black being its shadow); an undrawn canvas has nothing, i.e. 0.
const MIN_ANAGLYPH_LIT_SHARE = 0.3;
// The anaglyph against its definition, red from the left eye, green and blue from the right eye,
// in 8-bit codes; the blend-mode composition is exact (measured 0).
const MAX_ANAGLYPH_CODE_ERROR = 1;

const problems = [];
const report = {};
const t0 = Date.now();
const index = resolve(indexArg);
const browser = await chromium.launch({ executablePath: chromiumPath, headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'] });
try {
  const page = await browser.newPage({ viewport: { width: 1280, height: 1000 } });
  page.on('console', (m) => { if (m.type() === 'error') problems.push(`console error: ${m.text()}`); });
  page.on('pageerror', (e) => problems.push(`page error: ${e.message}`));
  page.on('requestfailed', (r) => problems.push(`request failed: ${r.url()} (${r.failure()?.errorText})`));
  page.on('request', (r) => {
    const u = r.url();
    if (!u.startsWith('file:') && !u.startsWith('data:')) problems.push(`network request from an offline report: ${u}`);
  });
  page.setDefaultTimeout(15000);

  await page.goto(pathToFileURL(index).href, { waitUntil: 'load' });
  await page.waitForFunction(() => document.documentElement.dataset.reportReady === 'true');
  const data = await page.evaluate(() => JSON.parse(document.getElementById('report-data').textContent));

  // Tables.
  const summaryRows = await page.locator('#summary tbody tr').count();
  if (summaryRows !== data.pipelines.length) problems.push(`summary table: ${summaryRows} rows for ${data.pipelines.length} pipelines`);
  const expectedCellRows = data.cells.reduce((n, c) => n + Object.keys(c.pipelines).length, 0);
  const cellRows = await page.locator('#cells tbody tr').count();
  if (cellRows !== expectedCellRows) problems.push(`cells table: ${cellRows} rows for ${expectedCellRows} (cell, pipeline) pairs`);
  const infinite = data.cells.reduce((n, c) => n + Object.values(c.pipelines).filter((p) => p.psnr === 'inf').length, 0);
  const shownInfinite = await page.evaluate(() => [...document.querySelectorAll('#cells tbody td')].filter((td) => td.textContent === '∞').length);
  if (shownInfinite < infinite) problems.push(`cells table shows ∞ ${shownInfinite} times for ${infinite} infinite PSNR values`);
  // The right eye's share of the left's: in the summary a number for a pipeline with one in any
  // cell, — otherwise; in the cells table a number exactly where the cell has one.
  // The column is the tables' last; a row's pipeline is its first td (summary: its th), since the
  // cells table's first row of a cell starts with the cell's th spanning the cell's rows.
  const column = (id) => page.evaluate((id) => {
    const heads = [...document.querySelectorAll(`#${id} thead th`)];
    if (!heads.length || heads[heads.length - 1].textContent !== 'Right / left %') return null;
    return [...document.querySelectorAll(`#${id} tbody tr`)].map((tr) =>
      [(tr.querySelector('td:not(.num)') || tr.querySelector('th')).textContent, tr.lastElementChild.textContent]);
  }, id);
  const shown = (has, text) => (has ? /^\d+\.\d$/.test(text) : text === '—');
  const summaryShares = await column('summary');
  if (summaryShares === null) problems.push('summary table: no "Right / left %" column');
  else for (const [pipeline, text] of summaryShares) {
    const has = data.cells.some((c) => c.pipelines[pipeline] && typeof c.pipelines[pipeline].right_over_left === 'number');
    if (!shown(has, text)) problems.push(`summary table: right / left of ${pipeline} shows "${text}"`);
  }
  const cellShares = await column('cells');
  if (cellShares === null) problems.push('cells table: no "Right / left %" column');
  else {
    const expected = data.cells.flatMap((c) => data.pipelines.filter((p) => c.pipelines[p])
      .map((p) => [p, typeof c.pipelines[p].right_over_left === 'number']));
    const wrong = cellShares.filter(([pipeline, text], i) => !expected[i] || expected[i][0] !== pipeline || !shown(expected[i][1], text));
    if (wrong.length) problems.push(`cells table: right / left shown wrongly in ${wrong.length} row(s), e.g. ${JSON.stringify(wrong[0])}`);
  }
  // Each cell's viewer label names all its axes: no two cells alike (convergences rounded to
  // centimetres merged 0.5 and 0.501 m).
  const cellLabels = await page.evaluate(() => [...document.querySelectorAll('details.cell > summary .sub')].map((s) => s.textContent));
  if (new Set(cellLabels).size !== cellLabels.length)
    problems.push(`viewer: ${cellLabels.length - new Set(cellLabels).size} cell label(s) repeat another cell's`);
  // Left eyes synthesized in part: a section exactly when some record measured one, with a summary
  // row per such pipeline and a row per measured (cell, pipeline) showing its left PSNR.
  const hasLeft = (p) => p && p.left_synthesized_fraction !== null && p.left_synthesized_fraction !== undefined;
  const leftPipelines = data.pipelines.filter((p) => data.cells.some((c) => hasLeft(c.pipelines[p])));
  const leftTables = await page.locator('#left-eyes table').count();
  if (!leftPipelines.length) {
    if (leftTables !== 0) problems.push('left eyes section shown, but no record measured a left eye');
  } else if (leftTables !== 2) {
    problems.push(`left eyes section: ${leftTables} tables for ${leftPipelines.length} pipeline(s) with a measured left eye`);
  } else {
    const rows = await page.evaluate(() => [...document.querySelectorAll('#left-eyes table')].map((t) =>
      [...t.querySelectorAll('tbody tr')].map((tr) => [...tr.children].map((x) => x.textContent))));
    if (rows[0].length !== leftPipelines.length)
      problems.push(`left eyes summary: ${rows[0].length} rows for ${leftPipelines.length} pipelines`);
    const expected = data.cells.flatMap((c) => leftPipelines.filter((p) => hasLeft(c.pipelines[p]))
      .map((p) => [p, c.pipelines[p].left_psnr]));
    if (rows[1].length !== expected.length) problems.push(`left eyes table: ${rows[1].length} rows for ${expected.length} measured left eyes`);
    expected.forEach(([p, psnr], i) => {
      const row = rows[1][i] || [];
      const at = row.indexOf(p);  // the pipeline cell; the left PSNR two columns on
      const want = psnr === 'inf' ? '∞' : psnr === null ? '—' : Number(psnr).toFixed(2);
      if (at < 0 || row[at + 2] !== want) problems.push(`left eyes table row ${i + 1}: ${JSON.stringify(row)}, expected ${p} with left PSNR ${want}`);
    });
    report.left_eye_rows = rows[1].length;
  }

  const bodyText = await page.evaluate(() => document.body.innerText);
  for (const bad of ['NaN', 'undefined', 'Infinity', '[object Object]'])
    if (bodyText.includes(bad)) problems.push(`the page text contains "${bad}"`);
  if (data.paper) {
    const paperRows = await page.locator('#paper tbody tr').count();
    if (paperRows === 0) problems.push(`paper section ${data.paper.experiment}: no table rows`);
    report.paper_rows = paperRows;
    // Kim's Table 1 (forward warping time): a row per method, with our time where the sweep ran it.
    if (data.paper.forward_warp) {
      const rows = await page.evaluate(() => {
        const tables = [...document.querySelectorAll('#paper table')];
        return [...tables[tables.length - 1].querySelectorAll('tbody tr')].map((tr) => [...tr.children].map((x) => x.textContent));
      });
      const methods = data.paper.forward_warp.methods;
      if (rows.length !== methods.length) problems.push(`forward warping table: ${rows.length} rows for ${methods.length} methods`);
      methods.forEach((m, i) => {
        const ran = data.cells.some((c) => c.pipelines[m.pipeline]);
        const ours = (rows[i] || [])[3];
        if (ran && !/^\d+\.\d{3}$/.test(ours || '')) problems.push(`forward warping table: ${m.pipeline} shows "${ours}"`);
      });
    }
  }

  // Charts: data drawn inside each plot area.
  const charts = await page.evaluate(() => [...document.querySelectorAll('figure.chart canvas')].map((canvas) => {
    const chart = window.Chart && Chart.getChart(canvas);
    if (!chart) return { title: canvas.getAttribute('aria-label'), pixels: 0, missing: true };
    const r = chart.currentDevicePixelRatio;
    const a = chart.chartArea;
    const x = Math.floor(a.left * r), y = Math.floor(a.top * r);
    const w = Math.max(1, Math.floor((a.right - a.left) * r)), h = Math.max(1, Math.floor((a.bottom - a.top) * r));
    const px = canvas.getContext('2d').getImageData(x, y, w, h).data;
    let saturated = 0;
    for (let i = 0; i < px.length; i += 4) {
      const hi = Math.max(px[i], px[i + 1], px[i + 2]), lo = Math.min(px[i], px[i + 1], px[i + 2]);
      if (px[i + 3] > 128 && hi - lo > 80) saturated++;
    }
    // Distinct positions of the drawn data elements (markers, line points, bars).
    const positions = new Set();
    chart.data.datasets.forEach((_, i) => {
      const meta = chart.getDatasetMeta(i);
      if (meta.hidden) return;
      for (const el of meta.data)
        if (Number.isFinite(el.x) && Number.isFinite(el.y)) positions.add(`${Math.round(el.x)},${Math.round(el.y)}`);
    });
    // A frame axis counts whole frames: its ticks (0, 0.5, 1, ... once) must be whole numbers.
    const xScale = chart.scales.x;
    const fractionalFrames = xScale && xScale.options.title && xScale.options.title.text === 'frame'
      ? xScale.ticks.filter((t) => !Number.isInteger(t.value)).length : 0;
    // Every legend entry drawn whole inside the legend and the canvas (Chart.js drops or cuts what
    // exceeds its legend's height), the plot area kept, and no two lines alike in colour, marker
    // and dash pattern.
    const lg = chart.legend;
    const cut = lg && lg.options.display !== false
      ? lg.legendItems.length - lg.legendHitBoxes.filter((b) => b.top >= lg.top - 1 && b.top + b.height <= lg.bottom + 1
        && b.top + b.height <= chart.height + 1).length : 0;
    // Alike: the same marker and dash, and colours less than 80 apart in RGB (two blues 29 apart
    // shared both, 8 pipelines apart; the palette's nearest colours, 43 apart, differ in marker).
    const rgb = (c) => (/^#[0-9a-f]{6}$/i.test(c) ? [1, 3, 5].map((i) => parseInt(c.slice(i, i + 2), 16)) : null);
    const lines = chart.config.type === 'line' ? chart.data.datasets : [];
    let alike = 0;
    for (let i = 0; i < lines.length; i++)
      for (let j = i + 1; j < lines.length; j++) {
        const a = lines[i], b = lines[j];
        if (a.pointStyle !== b.pointStyle || JSON.stringify(a.borderDash || []) !== JSON.stringify(b.borderDash || [])) continue;
        const ca = rgb(a.borderColor), cb = rgb(b.borderColor);
        const apart = ca && cb ? Math.hypot(ca[0] - cb[0], ca[1] - cb[1], ca[2] - cb[2]) : (a.borderColor === b.borderColor ? 0 : 255);
        if (apart < 80) alike++;
      }
    // The plot keeps its height: 200 px for lines, 24 px a bar for the stage bars (a bar chart
    // along time, the gate's, keeps its fixed box).
    const bars = chart.config.type === 'bar' && chart.options.indexAxis === 'y' ? chart.data.labels.length : 0;
    const plotNeed = chart.config.type === 'line' ? 150 : bars ? 20 * bars : 0;
    return { title: canvas.getAttribute('aria-label').split('.')[0], pixels: saturated, positions: positions.size,
      fractionalFrames, cut, alike, plotHeight: a.bottom - a.top, plotNeed };
  }));
  // The charts of every report: speed-up vs resolution, PSNR, SSIM, MSE and holes vs interaxial,
  // per-stage time (a chart without a finite value is left out and named in the caption).
  const minCharts = 6;
  if (charts.length < minCharts) problems.push(`${charts.length} charts, expected at least ${minCharts}`);
  for (const c of charts) {
    const need = c.missing ? MIN_CHART_DATA_PIXELS : Math.min(MIN_CHART_DATA_PIXELS, MIN_PIXELS_PER_POSITION * c.positions);
    if (!c.missing && c.positions === 0) problems.push(`chart "${c.title}": no data element laid out`);
    else if (c.pixels < need)
      problems.push(`chart "${c.title}": ${c.pixels} data pixels (< ${need})${c.missing ? ', no chart object' : ''}`);
  }
  for (const c of charts) {
    if (c.fractionalFrames) problems.push(`chart "${c.title}": ${c.fractionalFrames} ticks between whole frames`);
    if (c.cut) problems.push(`chart "${c.title}": ${c.cut} legend entries cut off or missing`);
    if (c.alike) problems.push(`chart "${c.title}": ${c.alike} lines drawn alike (colour, marker and dash)`);
    if (!c.missing && c.plotHeight < c.plotNeed)
      problems.push(`chart "${c.title}": plot area ${c.plotHeight.toFixed(0)} px high (< ${c.plotNeed})`);
  }
  report.charts = charts.map((c) => `${c.title}: ${c.pixels}`);

  // Trends (a report written with a history file): the median-time and gate-verdict charts always,
  // the PSNR chart unless every PSNR is infinite; one table row per run; each line chart holds one
  // point per run for every pipeline it plots.
  if (Array.isArray(data.history)) {
    const trends = await page.evaluate(() => {
      const section = document.getElementById('trends');
      if (!section) return null;
      return {
        rows: section.querySelectorAll('tbody tr').length,
        charts: [...section.querySelectorAll('figure.chart canvas')].map((canvas) => {
          const chart = window.Chart && Chart.getChart(canvas);
          return { title: canvas.getAttribute('aria-label').split('.')[0], type: chart ? chart.config.type : null,
            points: chart ? chart.data.datasets.map((d) => d.data.length) : [],
            // The plot's share of the chart's height, and the run axis labels' rotation.
            plotShare: chart ? chart.chartArea.height / chart.height : 0,
            rotation: chart ? chart.scales.x.labelRotation : 0,
            ticks: chart ? chart.scales.x.ticks.map((t) => ({ value: t.value, label: String(t.label) })) : [] };
        }),
      };
    });
    const runs = data.history.length;
    if (!trends) problems.push('the data has a history but the page has no #trends section');
    else if (runs > 0) {
      if (trends.rows !== runs) problems.push(`trends table: ${trends.rows} rows for ${runs} runs`);
      const finitePsnr = data.history.some((r) => Object.values(r.pipelines).some((p) => typeof p.psnr === 'number'));
      const expected = finitePsnr ? 3 : 2;
      if (trends.charts.length !== expected) problems.push(`trends: ${trends.charts.length} charts, expected ${expected}`);
      for (const c of trends.charts) {
        if (c.points.some((n) => n !== runs)) problems.push(`trend chart "${c.title}": datasets of ${c.points.join(', ')} points for ${runs} runs`);
        // A long history once left a strip of plot under rotated date-times.
        if (c.plotShare < 0.45) problems.push(`trend chart "${c.title}": the plot is ${(100 * c.plotShare).toFixed(0)} % of the chart's height (< 45 %)`);
        if (c.rotation !== 0) problems.push(`trend chart "${c.title}": run labels rotated ${c.rotation.toFixed(0)}°`);
        // Each tick names its own run: the start of that run's date and time.
        for (const t of c.ticks) {
          const run = data.history[t.value];
          const when = run ? String(run.date).replace('T', ' ') : '';
          if (!t.label || !when.startsWith(t.label)) problems.push(`trend chart "${c.title}": tick ${t.value} reads "${t.label}", its run is of ${when || 'no run'}`);
        }
      }
      report.trends = trends.charts.map((c) => `${c.title}: ${c.points.length} datasets of ${runs} points`);
    }
  }

  // A cell link of the cells table opens that cell's viewer (its images load) and shows it.
  if (data.cells.length > 1) {
    const link = page.locator('a[href^="#cell-"]').last();
    if (await link.count() === 0) {
      problems.push('no cell link in the tables');
    } else {
      const href = await link.getAttribute('href');
      await link.click();
      await page.waitForFunction((id) => {
        const d = document.getElementById(id);
        return d && d.open && d.querySelector('.views').children.length > 0;
      }, href.slice(1), { timeout: 5000 }).catch(() => problems.push(`the cell link ${href} did not open its viewer`));
      await page.locator(href).evaluate((d) => { d.open = false; });
    }
  }

  // Viewers: every cell, every pipeline, every mode.
  const modes = ['sbs', 'slider', 'flicker', 'anaglyph', 'holes', 'diff'];
  let imagesChecked = 0;
  report.anaglyph_lit = [];
  for (let ci = 0; ci < data.cells.length; ci++) {
    const cell = page.locator('details.cell').nth(ci);
    const cellId = await cell.getAttribute('id');
    await cell.evaluate((d) => { d.open = true; });
    await cell.scrollIntoViewIfNeeded();
    const select = cell.locator('select');
    const options = await select.locator('option').evaluateAll((os) => os.map((o) => o.value));
    for (const pipeline of options) {
      await select.selectOption(pipeline);
      // Every mode for every pipeline of the first cell and the first pipeline of the others: each
      // viewer's buttons are exercised, and the views are built the same for every pipeline.
      const cycle = !quick && (ci === 0 || pipeline === options[0]);
      for (const mode of cycle ? modes : []) {
        await cell.locator(`button[data-mode="${mode}"]`).click();
        const state = await cell.evaluate((d, m) => {
          const views = [...d.querySelectorAll('.view')];
          const visible = views.filter((v) => v.getClientRects().length > 0 && v.offsetHeight > 0).map((v) => v.dataset.view);
          const pressed = [...d.querySelectorAll('button[aria-pressed="true"]')].map((b) => b.dataset.mode);
          return { visible, pressed, missing: d.querySelectorAll(`.view[data-view="${m}"] .missing`).length };
        }, mode);
        const where = `cell ${ci + 1}, ${pipeline}, mode ${mode}`;
        if (state.visible.length !== 1 || state.visible[0] !== mode) problems.push(`${where}: visible views ${JSON.stringify(state.visible)}`);
        if (state.pressed.length !== 1 || state.pressed[0] !== mode) problems.push(`${where}: pressed buttons ${JSON.stringify(state.pressed)}`);
        if (state.missing) problems.push(`${where}: ${state.missing} image(s) not in the results`);

        if (mode === 'slider') {
          // Dragged where the divider is once the layout holds still: its images loaded (the box
          // takes their size) and the box in view (a pointer outside the viewport reaches nothing;
          // on a loaded machine the drag otherwise landed beside a box still growing).
          const compare = cell.locator('.compare');
          await compare.scrollIntoViewIfNeeded();
          await compare.evaluate(async (c) => {
            await Promise.all([...c.querySelectorAll('img')].map((i) => (i.complete ? null
              : new Promise((done) => { i.addEventListener('load', done, { once: true }); i.addEventListener('error', done, { once: true }); }))));
            await new Promise((done) => requestAnimationFrame(() => requestAnimationFrame(done)));
          });
          const box = await compare.boundingBox();
          if (!box) problems.push(`${where}: no slider`);
          else {
            await page.mouse.move(box.x + box.width * 0.5, box.y + box.height / 2);
            await page.mouse.down();
            await page.mouse.move(box.x + box.width * 0.25, box.y + box.height / 2, { steps: 4 });
            await page.mouse.up();
            const value = Number(await cell.locator('.range-row input[type="range"]').first().inputValue());
            if (Math.abs(value - 25) > 2) problems.push(`${where}: dragging the divider to 25 % left it at ${value} %`);
          }
        }
        if (mode === 'flicker' && pipeline === options[0]) {  // alternation once per cell: it takes 0.7 s
          const sel = `#${cellId} [data-view="flicker"] figcaption`;
          const before = await page.locator(sel).textContent();
          await page.waitForFunction(([s, b]) => document.querySelector(s).textContent !== b, [sel, before], { timeout: 3000 })
            .catch(() => problems.push(`${where}: flicker did not alternate within 3 s`));
        }
        if (mode === 'anaglyph') {
          const canvas = cell.locator('[data-view="anaglyph"] canvas');
          await page.waitForFunction((s) => document.querySelector(s)?.dataset.drawn === 'true',
            `#${cellId} [data-view="anaglyph"] canvas`, { timeout: 5000 })
            .catch(() => problems.push(`${where}: the anaglyph was not drawn`));
          // The canvas holds file:// images and cannot be read back here (the exact check below
          // reads it in a browser allowed to); its screenshot shows whether it was drawn at all.
          const png = (await canvas.screenshot()).toString('base64');
          const lit = await page.evaluate(async (b64) => {
            const img = new Image();
            img.src = `data:image/png;base64,${b64}`;
            await img.decode();
            const c = document.createElement('canvas');
            c.width = img.naturalWidth;
            c.height = img.naturalHeight;
            const ctx = c.getContext('2d');
            ctx.drawImage(img, 0, 0);
            const px = ctx.getImageData(0, 0, c.width, c.height).data;
            let n = 0;
            for (let i = 0; i < px.length; i += 4) if (Math.max(px[i], px[i + 1], px[i + 2]) > 20) n++;
            return n / (px.length / 4);
          }, png);
          report.anaglyph_lit.push(Number(lit.toFixed(3)));
          if (lit < MIN_ANAGLYPH_LIT_SHARE) problems.push(`${where}: the anaglyph canvas is ${(100 * lit).toFixed(1)} % lit (< ${100 * MIN_ANAGLYPH_LIT_SHARE} %)`);
        }
      }
      // Every image of the viewer, in every view, loaded.
      await cell.evaluate((d) => Promise.all([...d.querySelectorAll('img')].map((i) => (i.complete ? null : new Promise((r) => { i.onload = r; i.onerror = r; })))));
      const imgs = await cell.evaluate((d) => [...d.querySelectorAll('img')].map((i) => ({ src: i.getAttribute('src'), w: i.naturalWidth, alt: i.alt })));
      // Side by side 2, slider 2, flicker 1, hole overlay 2, difference 2.
      if (imgs.length < 9) problems.push(`cell ${ci + 1}, ${pipeline}: ${imgs.length} images in the viewer, expected 9`);
      // A pipeline with its own left eye (synthesized in part) shows it and its difference image.
      const own = data.cells[ci].pipelines[pipeline].images;
      for (const key of own.left ? ['left', 'left_diff'] : [])
        if (!imgs.some((i) => decodeURIComponent(i.src || '') === own[key])) problems.push(`cell ${ci + 1}, ${pipeline}: its ${key} image ${own[key]} is not in the viewer`);
      for (const i of imgs) {
        if (!(i.w > 0)) problems.push(`cell ${ci + 1}, ${pipeline}: image ${i.src} did not load`);
        if (!i.alt) problems.push(`cell ${ci + 1}, ${pipeline}: image ${i.src} has no alt text`);
      }
      imagesChecked += imgs.length;
    }
    await cell.locator('button[data-mode="slider"]').click();
    // Closing a cell drops its views and so its decoded images (a nightly report has thousands).
    await cell.evaluate((d) => { d.open = false; });
    await page.waitForFunction((id) => document.querySelector(`#${id} .views`).children.length === 0, cellId, { timeout: 3000 })
      .catch(() => problems.push(`cell ${ci + 1}: closing it kept its views`));
  }
  report.images_checked = imagesChecked;
  // Reopened, the first cell builds its views again, in the mode it was left in.
  const first = page.locator('details.cell').first();
  await first.evaluate((d) => { d.open = true; });
  await page.waitForFunction(() => {
    const d = document.querySelector('details.cell');
    const view = d.querySelector('.view[data-view="slider"]');
    return view && !view.hidden && [...view.querySelectorAll('img')].every((i) => i.complete && i.naturalWidth > 0);
  }, null, { timeout: 10000 }).catch(() => problems.push('cell 1: reopened, it did not show its slider view with loaded images'));
  if (!quick) {
    await page.locator('details.cell').first().locator('button[data-mode="anaglyph"]').click();
    await page.locator('details.cell').first().locator('[data-view="anaglyph"] canvas[data-drawn="true"]').waitFor();
  }
  await page.evaluate(() => window.scrollTo(0, 0));
  await page.screenshot({ path: resolve(screenshotArg), fullPage: true });
} catch (e) {
  problems.push(`check failed: ${e.message}`);
} finally {
  await browser.close();
}

report.main_s = (Date.now() - t0) / 1000;

// The anaglyph composition, pixel by pixel: a browser allowed to read file:// images back.
const exact = quick ? null : await chromium.launch({ executablePath: chromiumPath, headless: true,
  args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage', '--allow-file-access-from-files'] });
try {
  if (!exact) throw new Error('skipped');
  const page = await exact.newPage({ viewport: { width: 1280, height: 1000 } });
  page.setDefaultTimeout(15000);
  await page.goto(pathToFileURL(index).href, { waitUntil: 'load' });
  await page.waitForFunction(() => document.documentElement.dataset.reportReady === 'true');
  const count = await page.locator('details.cell').count();
  report.anaglyph_max_error = 0;
  for (let ci = 0; ci < count; ci++) {
    const cell = page.locator('details.cell').nth(ci);
    await cell.evaluate((d) => { d.open = true; });
    await cell.locator('button[data-mode="anaglyph"]').click();
    for (const pipeline of await cell.locator('select option').evaluateAll((os) => os.map((o) => o.value))) {
      await cell.locator('select').selectOption(pipeline);
      await cell.locator('[data-view="anaglyph"] canvas[data-drawn="true"]').waitFor();
      const err = await cell.evaluate(async (d, [ci2, p]) => {
        const data = JSON.parse(document.getElementById('report-data').textContent);
        const c = data.cells[ci2];
        const pixels = async (path) => {
          const img = new Image();
          img.src = path.split('/').map((s) => (s === '..' ? s : encodeURIComponent(s))).join('/');
          await img.decode();
          const cv = document.createElement('canvas');
          cv.width = img.naturalWidth;
          cv.height = img.naturalHeight;
          const ctx = cv.getContext('2d');
          ctx.drawImage(img, 0, 0);
          return ctx.getImageData(0, 0, cv.width, cv.height).data;
        };
        const left = await pixels(c.pipelines[p].images.left || c.images.left);
        const right = await pixels(c.pipelines[p].images.right);
        const canvas = d.querySelector('[data-view="anaglyph"] canvas');
        const got = canvas.getContext('2d').getImageData(0, 0, canvas.width, canvas.height).data;
        if (got.length !== left.length) return 1e9;
        let max = 0;
        for (let i = 0; i < got.length; i += 4)
          max = Math.max(max, Math.abs(got[i] - left[i]), Math.abs(got[i + 1] - right[i + 1]), Math.abs(got[i + 2] - right[i + 2]));
        return max;
      }, [ci, pipeline]);
      report.anaglyph_max_error = Math.max(report.anaglyph_max_error, err);
      if (err > MAX_ANAGLYPH_CODE_ERROR) problems.push(`cell ${ci + 1}, ${pipeline}: anaglyph differs from (left R, right G, right B) by ${err} codes`);
    }
  }
} catch (e) {
  if (exact) problems.push(`anaglyph check failed: ${e.message}`);
} finally {
  if (exact) await exact.close();
}

report.total_s = (Date.now() - t0) / 1000;
console.log(`check_report: ${index}: ${JSON.stringify(report)}`);
if (problems.length) {
  console.log(`check_report: ${problems.length} problem(s):\n  ${problems.join('\n  ')}`);
  process.exit(1);
}
console.log('check_report: ok');
