// End-to-end tests of `primseg view` in a real browser (Debian's chromium, headless).
// PRIMSEG: the CLI (default ../build/primseg); PRIMSEG_WEB_ARTIFACTS: where screenshots go.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync, spawnSync } from 'node:child_process';
import { mkdirSync, mkdtempSync, readFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { launchBrowser, openViewer } from './browser.mjs';
import { writeBook, writeGridBox } from './meshes.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const cli = resolve(process.env.PRIMSEG ?? join(here, '../../build/primseg'));
const artifacts = resolve(process.env.PRIMSEG_WEB_ARTIFACTS ?? join(tmpdir(), 'primseg-web-artifacts'));
const work = mkdtempSync(join(tmpdir(), 'primseg-web-'));
mkdirSync(artifacts, { recursive: true });

function primseg(...args) {
  return execFileSync(cli, args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
}
const readLabels = (file) => readFileSync(file, 'utf8').trim().split('\n').map(Number);

let browser, fandisk;
before(async () => {
  browser = await launchBrowser();
  execFileSync('tar', ['xzf', '/usr/share/doc/libcgal-dev/data.tar.gz', '-C', work, 'data/meshes/fandisk.off']);
  fandisk = join(work, 'data/meshes/fandisk.off');
  primseg('segment', fandisk, '--tree', join(work, 'fandisk.tree'), '--quiet');
  primseg('view', fandisk, '--tree', join(work, 'fandisk.tree'), '--clusters', '27', '-o', join(work, 'fandisk.html'), '--quiet');
});
after(async () => browser?.close());

/**
 * Asserts that the page's face labels are the CLI's: the same clusters, numbered alike (by
 * decreasing area) but for clusters whose areas are equal up to the precision of the page's
 * float32 positions. `area`: the CLI's cluster areas (its JSON).
 */
function assertSameLabels(labels, expected, area, diagonal, what) {
  assert.equal(labels.length, expected.length);
  // The same clusters: page label p is CLI label cliOf[p], one to one.
  const cliOf = new Map(), pageOf = new Map();
  labels.forEach((p, f) => {
    if (!cliOf.has(p)) cliOf.set(p, expected[f]);
    if (!pageOf.has(expected[f])) pageOf.set(expected[f], p);
    assert.equal(cliOf.get(p), expected[f], `${what}: face ${f} is not in the CLI's cluster`);
    assert.equal(pageOf.get(expected[f]), p, `${what}: face ${f} is not in the page's cluster`);
  });
  assert.equal(cliOf.size, area.length);
  let renumbered = 0;
  for (const [p, q] of cliOf)
    if (p !== q) {
      ++renumbered;
      assert.ok(Math.abs(area[p] - area[q]) <= 1e-4 * area[q] + 1e-10 * diagonal ** 2, `${what}: cluster ${q} numbered ${p}`);
    }
  if (renumbered) console.log(`# ${what}: ${renumbered} of ${area.length} clusters of near-equal area numbered in another order`);
}

/**
 * Asserts that the page's report of a cluster (its click panel) is primseg cut's (its JSON):
 * the same geometric fit and the same exact errors. The page gets primseg's numbers as doubles:
 * RMS and max are equal; the parameters are too, but for the round-off of the page's centring
 * (point − center + center), far below 1e-12 of the diagonal.
 */
function assertSameReport(info, expected, diagonal, what) {
  assert.equal(info.type, expected.type, what);
  assert.equal(info.faces, expected.faces, what);
  assert.ok(Math.abs(info.area - expected.area) < 1e-5 * expected.area, `${what}: area ${info.area} vs ${expected.area}`);
  assert.equal(info.rms, expected.rms, `${what}: rms`);
  assert.equal(info.max, expected.max, `${what}: max`);
  assert.deepEqual(Object.keys(info.params).sort(), Object.keys(expected.params).sort(), what);
  for (const [key, value] of Object.entries(expected.params)) {
    const shown = info.params[key];
    const length = /radius|center|point|apex/.test(key) ? diagonal : 1;  // angles, unit vectors: 1
    const values = Array.isArray(value) ? value : [value], got = Array.isArray(shown) ? shown : [shown];
    values.forEach((v, a) => assert.ok(Math.abs(got[a] - v) <= 1e-12 * length, `${what}: ${key} ${got} vs ${values}`));
  }
}

/** The canvas's RGBA pixels seen from each of the six axis directions, in turn. */
async function* axisViewPixels(page) {
  for (const direction of [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]) {
    const { rgba } = await page.evaluate(async (d) => {
      const viewer = await window.primseg.ready;
      viewer.setView(d);
      return viewer.readPixels();
    }, direction);
    yield Buffer.from(rgba, 'base64');
  }
}

/** Distinct non-background colours drawn from six axis views, as cluster indices (code - 1). */
async function drawnClusters(page) {
  const codes = new Set();
  for await (const pixels of axisViewPixels(page))
    for (let i = 0; i < pixels.length; i += 4) {
      const code = pixels[i] | (pixels[i + 1] << 8) | (pixels[i + 2] << 16);
      if (code) codes.add(code - 1);
    }
  return codes;
}

test('a generated box: no console error, no network, exactly K cluster colours drawn', async () => {
  const mesh = join(work, 'box.off'), html = join(work, 'box.html');
  const triangles = writeGridBox(mesh, 8);
  primseg('view', mesh, '-o', html, '--quiet');
  const { page, errors, requests } = await openViewer(browser, html, { test: true, width: 640, height: 480 });
  for (const K of [1, 3, 6, 20, 100, triangles]) {
    const size = await page.evaluate(async (k) => {
      const viewer = await window.primseg.ready;
      viewer.setClusters(k);
      return viewer.cut.size;
    }, K);
    assert.equal(size, K);
    const drawn = await drawnClusters(page);
    assert.equal(drawn.size, K, `K = ${K}: ${drawn.size} colours drawn`);
    assert.ok(Math.max(...drawn) < K, 'every colour is a cluster code');
  }
  await page.screenshot({ path: join(artifacts, 'box-test-mode.png') });
  assert.deepEqual(errors, []);
  assert.deepEqual(requests, []);
  await page.close();
});

test('fandisk: the page cuts the same levels as primseg cut, by count and by tolerance', async () => {
  const { page, errors } = await openViewer(browser, join(work, 'fandisk.html'));
  const tree = join(work, 'fandisk.tree'), labelsFile = join(work, 'cut.labels');
  const levels = [['--clusters', '1'], ['--clusters', '5'], ['--clusters', '27'], ['--clusters', '300'],
    ['--clusters', '5000'], ['--clusters', '12946'], ['--tolerance', '0.1%'], ['--tolerance', '1%'], ['--tolerance', '0']];
  const diagonal = await page.evaluate(async () => (await window.primseg.ready).header.bboxDiagonal);
  for (const [option, value] of levels) {
    const jsonFile = join(work, 'cut.json');
    primseg('cut', tree, option, value, '--labels', labelsFile, '--json', jsonFile, '--quiet');
    const expected = readLabels(labelsFile);
    const area = JSON.parse(readFileSync(jsonFile, 'utf8')).clusters.map((c) => c.area);
    const tolerance = value.endsWith('%') ? (Number(value.slice(0, -1)) / 100) * diagonal : Number(value);
    const labels = await page.evaluate(async ([byCount, x]) => {
      const viewer = await window.primseg.ready;
      if (byCount) viewer.setClusters(x);
      else viewer.setTolerance(x);
      return viewer.labels();
    }, [option === '--clusters', option === '--clusters' ? Number(value) : tolerance]);
    assertSameLabels(labels, expected, area, diagonal, `${option} ${value}`);
  }
  assert.deepEqual(errors, []);
  await page.close();
});

test('fandisk: the automatic levels are marked on the plot and offered as buttons; each cuts as primseg cut', async () => {
  const tree = join(work, 'fandisk.tree'), labelsFile = join(work, 'auto.labels'), jsonFile = join(work, 'auto.json');
  primseg('cut', tree, '--clusters', 'auto', '--json', jsonFile, '--quiet');
  const level = JSON.parse(readFileSync(jsonFile, 'utf8')).level;
  assert.ok(level.candidates.length >= 2, 'fandisk has several candidate levels');
  const { page, errors } = await openViewer(browser, join(work, 'fandisk.html'));
  const shown = await page.evaluate(async () => {
    const viewer = await window.primseg.ready;
    const canvas = document.getElementById('plot'), rect = canvas.getBoundingClientRect();
    const ratio = canvas.width / canvas.clientWidth, g = canvas.getContext('2d');
    // Each mark: its place on the plot, and whether it is drawn there (the marks' yellow).
    const marks = viewer.plot.levelMarks().map(({ clusters, x, y }) => {
      const [r, gr, b] = g.getImageData(Math.round(x * ratio), Math.round(y * ratio), 1, 1).data;
      return { clusters, x: rect.left + x, y: rect.top + y, drawn: r > 200 && gr > 150 && b < 160 };
    });
    return { levels: viewer.header.levels, autoLevel: viewer.header.autoLevel, marks,
      plot: [rect.left, rect.top, rect.width, rect.height],
      buttons: Array.from(document.querySelectorAll('#levels button'), (b) => Number(b.dataset.clusters)) };
  });
  // The page's levels are primseg's: same K and scores, the same chosen level.
  assert.deepEqual(shown.levels.map((l) => [l.clusters, l.score, l.mergeScore]),
    level.candidates.map((c) => [c.clusters, c.score, c.merge_score]));
  assert.equal(shown.autoLevel, level.clusters);
  const Ks = level.candidates.map((c) => c.clusters).sort((a, b) => a - b);
  assert.deepEqual(shown.buttons, Ks);
  assert.deepEqual(shown.marks.map((m) => m.clusters), Ks);
  for (const mark of shown.marks) {
    assert.ok(mark.drawn, `the mark of K = ${mark.clusters} is drawn`);
    const [left, top, width, height] = shown.plot;
    assert.ok(mark.x >= left && mark.x <= left + width && mark.y >= top && mark.y <= top + height);
  }
  const diagonal = await page.evaluate(async () => (await window.primseg.ready).header.bboxDiagonal);
  const state = () => page.evaluate(async () => {
    const viewer = await window.primseg.ready;
    return { size: viewer.cut.size, slider: Number(document.getElementById('clusters-slider').value),
      expectedSlider: viewer.sliderOf(viewer.cut.size), input: Number(document.getElementById('clusters-input').value),
      labels: viewer.labels() };
  });
  for (const K of Ks) {
    await page.evaluate(async () => (await window.primseg.ready).setClusters(1));
    await page.click(`#levels button[data-clusters="${K}"]`);
    const after = await state();
    assert.equal(after.size, K);
    assert.equal(after.input, K);
    assert.equal(after.slider, after.expectedSlider, `the slider is at K = ${K}`);
    primseg('cut', tree, '--clusters', String(K), '--labels', labelsFile, '--json', jsonFile, '--quiet');
    const area = JSON.parse(readFileSync(jsonFile, 'utf8')).clusters.map((c) => c.area);
    assertSameLabels(after.labels, readLabels(labelsFile), area, diagonal, `level ${K}`);
    // A click on its mark goes to the same level (marks closer than a pixel aside).
    const mark = shown.marks.find((m) => m.clusters === K);
    if (shown.marks.some((m) => m !== mark && Math.abs(m.x - mark.x) < 1)) continue;
    await page.evaluate(async () => (await window.primseg.ready).setClusters(1));
    await page.mouse.click(mark.x, mark.y - 10);
    assert.equal((await state()).size, K, `a click on the mark of K = ${K}`);
  }
  assert.deepEqual(errors, []);
  await page.close();
});

test('fandisk: a click reports the cluster under the pointer, as primseg reports it', async () => {
  const K = 27;
  primseg('cut', join(work, 'fandisk.tree'), '--clusters', String(K), '--labels', join(work, 'k.labels'),
    '--json', join(work, 'k.json'), '--quiet');
  const labels = readLabels(join(work, 'k.labels'));
  const clusters = JSON.parse(readFileSync(join(work, 'k.json'), 'utf8')).clusters;
  const { page, errors } = await openViewer(browser, join(work, 'fandisk.html'), { test: true, width: 800, height: 600 });
  const { width, height, rgba } = await page.evaluate(async () => (await window.primseg.ready).readPixels());
  const pixels = Buffer.from(rgba, 'base64');
  // A pixel well inside each of a few clusters: one whose neighbours all have its colour.
  const code = (x, y) => { const i = 4 * (y * width + x); return pixels[i] | (pixels[i + 1] << 8) | (pixels[i + 2] << 16); };
  const targets = new Map();
  for (let y = 10; y < height - 10 && targets.size < 6; y += 7)
    for (let x = 10; x < width - 10; x += 7) {
      const c = code(x, y);
      if (!c || targets.has(c) || ![[-4, 0], [4, 0], [0, -4], [0, 4]].every(([dx, dy]) => code(x + dx, y + dy) === c))
        continue;
      // Not under one of the page's panels (the info panel appears after the first click).
      const onCanvas = await page.evaluate(([px, py]) => {
        const below = document.elementsFromPoint(px, py);
        return below[0]?.id === 'view' && !below.some((e) => e.classList.contains('panel'));
      }, [x, height - 1 - y]);
      const clear = onCanvas && !(x < 420 && height - 1 - y > height - 320);
      if (clear) targets.set(c, [x, y]);
    }
  assert.ok(targets.size >= 3, 'several clusters are visible');
  for (const [c, [x, y]] of targets) {
    await page.evaluate(async () => ((await window.primseg.ready).info = null));
    await page.mouse.click(x, height - 1 - y); // readPixels rows go bottom-up
    const info = await page.evaluate(async () => (await window.primseg.ready).info);
    assert.ok(info, `a click at (${x}, ${y}) selects a cluster`);
    const cutIndex = await page.evaluate(async (face) => (await window.primseg.ready).cut.faceCluster[face], info.face);
    assert.equal(cutIndex, c - 1, 'the clicked face is in the cluster drawn there');
    const expected = clusters[labels[info.face]];
    assert.equal(info.id, expected.id);
    assert.equal(info.clusters, K);
    assert.equal(info.type, expected.type);
    assert.equal(info.faces, expected.faces);
    const panel = await page.textContent('#info');
    assert.match(panel, new RegExp(`cluster ${expected.id} of ${K}`));
    assertSameReport(info, expected, 1.2 /* fandisk's diagonal, about */, `cluster ${expected.id}`);
    for (const row of ['RMS', 'max error']) assert.ok(panel.includes(row), `the panel shows the ${row}`);
  }
  assert.deepEqual(errors, []);
  await page.close();
});

test('fandisk: every cluster\'s panel shows the fit and errors primseg cut reports, at every kind of level', async () => {
  const { page, errors } = await openViewer(browser, join(work, 'fandisk.html'));
  const tree = join(work, 'fandisk.tree'), labelsFile = join(work, 'panel.labels'), jsonFile = join(work, 'panel.json');
  const diagonal = await page.evaluate(async () => (await window.primseg.ready).header.bboxDiagonal);
  const seen = new Set();
  // Coarse levels, one where single faces are clusters, and a level by tolerance.
  for (const [option, value] of [['--clusters', '1'], ['--clusters', '27'], ['--clusters', '300'],
    ['--clusters', '9000'], ['--tolerance', '0.1%']]) {
    primseg('cut', tree, option, value, '--labels', labelsFile, '--json', jsonFile, '--quiet');
    const labels = readLabels(labelsFile), clusters = JSON.parse(readFileSync(jsonFile, 'utf8')).clusters;
    const tolerance = value.endsWith('%') ? (Number(value.slice(0, -1)) / 100) * diagonal : 0;
    // As JSON text: Playwright passes thousands of objects one by one (5 s at 9,000 clusters).
    const shown = JSON.parse(await page.evaluate(async ([byCount, x]) => {
      const viewer = await window.primseg.ready;
      if (byCount) viewer.setClusters(x);
      else viewer.setTolerance(x);
      const faceCluster = viewer.cut.faceCluster, first = new Int32Array(viewer.cut.size).fill(-1);
      faceCluster.forEach((c, f) => { if (first[c] < 0) first[c] = f; });
      return JSON.stringify(Array.from(first, (face, c) => ({ face, ...viewer.describe(c, face) })));
    }, [option === '--clusters', option === '--clusters' ? Number(value) : tolerance]));
    assert.equal(shown.length, clusters.length);
    for (const info of shown) {
      const expected = clusters[labels[info.face]];
      assertSameReport(info, expected, diagonal, `${option} ${value}, cluster ${expected.id}`);
      seen.add(expected.type);
    }
  }
  for (const type of ['plane', 'cylinder', 'sphere']) assert.ok(seen.has(type), `a ${type} cluster is compared`);
  assert.deepEqual(errors, []);
  await page.close();
});

test('fandisk: screenshot with the fitted primitives drawn', async () => {
  const { page, errors } = await openViewer(browser, join(work, 'fandisk.html'), { width: 1100, height: 700 });
  await page.check('#show-primitives');
  const { drawn, surfaces } = await page.evaluate(async () => {
    const viewer = await window.primseg.ready;
    const faceCluster = viewer.cut.faceCluster;
    // Each drawn surface with a face of its cluster and its parameters as the panel shows them.
    const surfaces = viewer.drawnPrimitives.map((c) => {
      const face = faceCluster.indexOf(c);
      return { face, ...viewer.describe(c, face) };
    });
    return { drawn: viewer.primitiveMesh ? viewer.primitiveMesh.geometry.index.count / 3 : 0, surfaces };
  });
  assert.ok(drawn > 0, 'primitive surfaces are drawn');
  // The surfaces drawn are primseg's reported (geometric) fits, one per cluster of the level.
  primseg('cut', join(work, 'fandisk.tree'), '--clusters', '27', '--labels', join(work, 'd.labels'),
    '--json', join(work, 'd.json'), '--quiet');
  const labels = readLabels(join(work, 'd.labels'));
  const clusters = JSON.parse(readFileSync(join(work, 'd.json'), 'utf8')).clusters;
  assert.equal(surfaces.length, 27);
  for (const info of surfaces) assertSameReport(info, clusters[labels[info.face]], 1.2, `drawn cluster ${info.id}`);
  await page.uncheck('#show-primitives');
  await page.selectOption('#color-mode', 'type');
  await page.screenshot({ path: join(artifacts, 'fandisk-types.png') });
  await page.selectOption('#color-mode', 'cluster');
  await page.screenshot({ path: join(artifacts, 'fandisk.png') });
  assert.deepEqual(errors, []);
  await page.close();
});

/** The edges of primseg's border curves (its JSON), as "lower,higher" vertex pairs. */
function borderEdgesOf(json) {
  const edges = new Set();
  for (const border of json.borders)
    for (const { vertices, closed } of border.curves) {
      const ring = closed ? [...vertices, vertices[0]] : vertices;
      for (let i = 0; i + 1 < ring.length; ++i)
        edges.add([Math.min(ring[i], ring[i + 1]), Math.max(ring[i], ring[i + 1])].join());
    }
  return edges;
}

/** Pixels of exactly this colour drawn from six axis views (test mode). */
async function pixelsOfColor(page, rgb) {
  let count = 0;
  for await (const pixels of axisViewPixels(page))
    for (let i = 0; i < pixels.length; i += 4)
      count += pixels[i] === rgb[0] && pixels[i + 1] === rgb[1] && pixels[i + 2] === rgb[2] ? 1 : 0;
  return count;
}

test('fandisk: the borders drawn are the edges of primseg\'s border curves, at every level', async () => {
  const { page, errors } = await openViewer(browser, join(work, 'fandisk.html'), { test: true, width: 640, height: 480 });
  assert.equal(await pixelsOfColor(page, [255, 255, 255]), 0, 'no border line before the box is ticked');
  await page.check('#show-borders');
  for (const K of [27, 5, 300, 12946]) {
    const jsonFile = join(work, 'borders.json');
    primseg('cut', join(work, 'fandisk.tree'), '--clusters', String(K), '--json', jsonFile, '--quiet');
    const expected = borderEdgesOf(JSON.parse(readFileSync(jsonFile, 'utf8')));
    const drawn = await page.evaluate(async (k) => {
      const viewer = await window.primseg.ready;
      viewer.setClusters(k);
      return viewer.borderLines.borderEdges().map((e) => e.join());
    }, K);
    assert.equal(drawn.length, expected.size, `K = ${K}`);
    assert.deepEqual(new Set(drawn), expected, `K = ${K}`);
  }
  await page.evaluate(async () => (await window.primseg.ready).setClusters(27));
  assert.ok(await pixelsOfColor(page, [255, 255, 255]) > 100, 'border lines are drawn');
  await page.uncheck('#show-borders');
  assert.equal(await pixelsOfColor(page, [255, 255, 255]), 0, 'no border line once unticked');
  assert.deepEqual(errors, []);
  await page.close();

  // A picture for the eye.
  const shown = await openViewer(browser, join(work, 'fandisk.html'), { width: 1100, height: 700 });
  await shown.page.check('#show-borders');
  await shown.page.screenshot({ path: join(artifacts, 'fandisk-borders.png') });
  assert.deepEqual(shown.errors, []);
  await shown.page.close();
});

/**
 * Asserts that at K clusters every cluster's panel on the page `html` lists its borders as `primseg
 * cut TREE --clusters K --json` reports them (neighbours, edge counts, lengths and angles).
 */
async function assertPanelsListTheCutsBorders(page, tree, K) {
  primseg('cut', tree, '--clusters', String(K), '--labels', join(work, 'm.labels'),
    '--json', join(work, 'm.json'), '--quiet');
  const cliLabels = readLabels(join(work, 'm.labels'));
  const borders = JSON.parse(readFileSync(join(work, 'm.json'), 'utf8')).borders;
  const { pageLabels, panels } = await page.evaluate(async (K) => {
    const viewer = await window.primseg.ready;
    viewer.setClusters(K);
    const faceCluster = viewer.cut.faceCluster;
    const panels = [];
    for (let c = 0; c < viewer.cut.size; ++c) panels.push(viewer.describe(c, faceCluster.indexOf(c)));
    return { pageLabels: viewer.labels(), panels };
  }, K);
  // Page ids to primseg's (the same clusters; ids of near-equal areas may differ).
  const cliOf = new Map();
  pageLabels.forEach((p, f) => cliOf.set(p, cliLabels[f]));
  const byOther = (x, y) => (x.other ?? -1) - (y.other ?? -1); // the open boundary first
  let compared = 0;
  for (const panel of panels) {
    const id = cliOf.get(panel.id);
    const expected = borders.filter((b) => b.clusters.includes(id))
      .map((b) => ({ other: b.clusters[0] === id ? b.clusters[1] : b.clusters[0], ...b }))
      .sort(byOther);
    const shown = panel.borders.map((b) => ({ ...b, other: b.cluster === null ? null : cliOf.get(b.cluster) }))
      .sort(byOther);
    assert.deepEqual(shown.map((b) => b.other), expected.map((b) => b.other), `cluster ${id}: neighbours`);
    shown.forEach((b, i) => {
      const e = expected[i], what = `cluster ${id} meets ${e.other}`;
      assert.equal(b.edges, e.edges, what);
      assert.ok(Math.abs(b.length - e.length) <= 1e-5 * e.length, `${what}: length ${b.length} vs ${e.length}`);
      if (e.angle === null) assert.equal(b.angle, null, what);
      else assert.ok(Math.abs(b.angle - e.angle) <= 1e-3, `${what}: angle ${b.angle} vs ${e.angle}`);
      ++compared;
    });
  }
  // Each border between two clusters is listed by both, one along the open boundary by its own.
  const boundary = borders.filter((b) => b.clusters.includes(null)).length;
  assert.equal(compared, 2 * borders.length - boundary);
  return borders;
}

test('fandisk: a cluster\'s panel lists its borders as primseg cut reports them', async () => {
  const { page, errors } = await openViewer(browser, join(work, 'fandisk.html'));
  await assertPanelsListTheCutsBorders(page, join(work, 'fandisk.tree'), 27);
  // The panel shows them.
  const text = await page.evaluate(async () => {
    const viewer = await window.primseg.ready;
    viewer.showInfo(viewer.describe(0, viewer.cut.faceCluster.indexOf(0)));
    return document.getElementById('info').textContent;
  });
  assert.match(text, /meets.*\d+ \((plane|cylinder|sphere)\) at \d+\.\d°/);
  assert.deepEqual(errors, []);
  await page.close();
});

test('a book (9 triangles on one edge): the panels list the borders primseg cut reports', async () => {
  const mesh = join(work, 'book.off'), tree = join(work, 'book.tree'), html = join(work, 'book.html');
  writeBook(mesh, 9);
  primseg('segment', mesh, '--tree', tree, '--quiet');
  primseg('view', mesh, '--tree', tree, '--clusters', '9', '-o', html, '--quiet');
  const { page, errors } = await openViewer(browser, html);
  for (const K of [9, 5, 2]) {
    const borders = await assertPanelsListTheCutsBorders(page, tree, K);
    // The spine is in the borders of the pages the dual graph links (each to the next), not in
    // every pair's: one edge per border between clusters.
    const between = borders.filter((b) => !b.clusters.includes(null));
    assert.ok(between.length <= K - 1, `${K} clusters: ${between.length} borders on the spine`);
    for (const b of between) assert.equal(b.edges, 1);
  }
  assert.deepEqual(errors, []);
  await page.close();
});

test('fandisk --regularize: each level lists primseg cut --regularize\'s relations and reports its exact fits', async () => {
  const html = join(work, 'fandisk-relations.html'), tree = join(work, 'fandisk.tree');
  primseg('view', fandisk, '--tree', tree, '--clusters', '27', '--regularize', '-o', html, '--quiet');
  const { page, errors } = await openViewer(browser, html);
  const diagonal = await page.evaluate(async () => (await window.primseg.ready).header.bboxDiagonal);
  const kinds = new Set();
  let refitted = 0, tangentCylinders = 0;
  for (const K of [1, 10, 27, 34, 60, 100]) {
    const labelsFile = join(work, 'r.labels'), jsonFile = join(work, 'r.json');
    primseg('cut', tree, '--clusters', String(K), '--regularize', '--labels', labelsFile, '--json', jsonFile, '--quiet');
    const cliLabels = readLabels(labelsFile), cli = JSON.parse(readFileSync(jsonFile, 'utf8'));
    const shown = await page.evaluate(async (k) => {
      const viewer = await window.primseg.ready;
      viewer.setClusters(k);
      const first = new Int32Array(viewer.cut.size).fill(-1);
      viewer.cut.faceCluster.forEach((c, f) => { if (first[c] < 0) first[c] = f; });
      return { labels: viewer.labels(), relations: viewer.currentRelations(),
        rows: Array.from(document.querySelectorAll('#relations .relation'), (row) => row.textContent),
        panels: Array.from(first, (face, c) => ({ face, ...viewer.describe(c, face) })) };
    }, K);
    // Page ids to primseg's, through the faces (ids of near-equal areas may differ).
    const cliOf = new Map();
    shown.labels.forEach((p, f) => cliOf.set(p, cliLabels[f]));
    const asCli = (ids) => ids.map((id) => cliOf.get(id)).sort((a, b) => a - b);
    const relations = shown.relations.map((r) => ({ ...r, clusters: asCli(r.clusters),
      ...(r.orthogonal_to ? { orthogonal_to: asCli(r.orthogonal_to) } : {}) }));
    assert.deepEqual(relations, cli.relations, `K = ${K}: the relations`);
    assert.equal(shown.rows.length, cli.relations.length, `K = ${K}: one row per relation`);
    // Each row says how far the own fits were from its relation, as primseg reports it.
    cli.relations.forEach((r, i) => {
      const deviation = Number(/off by ([-0-9.e+]+)/.exec(shown.rows[i])?.[1]);
      assert.ok(Math.abs(deviation - r.deviation) <= 1e-4 * r.deviation, `K = ${K}: ${shown.rows[i]}`);
    });
    // A tangent pair's row names its cylinders' radii (one, or two for a fillet and a cylinder),
    // as primseg reports them.
    cli.relations.forEach((r, i) => {
      if (r.kind !== 'tangent') return;
      const radii = r.clusters.map((c) => cli.clusters[c]).filter((c) => c.type === 'cylinder')
        .map((c) => c.params.radius).sort((a, b) => a - b);
      const listed = /r = ([-0-9.e+]+)(?: and ([-0-9.e+]+))?/.exec(shown.rows[i]).slice(1)
        .filter((x) => x !== undefined).map(Number).sort((a, b) => a - b);
      assert.equal(listed.length, radii.length, `K = ${K}: ${shown.rows[i]}`);
      listed.forEach((radius, k) => assert.ok(Math.abs(radius - radii[k]) <= 1e-3 * radii[k], `K = ${K}: ${shown.rows[i]}`));
      if (radii.length === 2) ++tangentCylinders;
    });
    for (const r of cli.relations) kinds.add(r.kind);
    // Every cluster's panel: the fit as cut --regularize reports it (the members' made exact),
    // and the relations it is in.
    for (const info of shown.panels) {
      const expected = cli.clusters[cliLabels[info.face]];
      assertSameReport(info, expected, diagonal, `K = ${K}, cluster ${expected.id}`);
      const member = cli.relations.filter((r) => r.clusters.includes(expected.id) || r.orthogonal_to?.includes(expected.id));
      assert.equal(info.relations.length, member.length, `K = ${K}, cluster ${expected.id}: its relations`);
      if (member.length) ++refitted;
    }
  }
  for (const kind of ['parallel', 'coaxial', 'orthogonal', 'equal_radius', 'tangent']) assert.ok(kinds.has(kind), `a ${kind} relation is compared`);
  assert.ok(tangentCylinders >= 2, `${tangentCylinders} fillets tangent to a cylinder compared`);
  assert.ok(refitted > 50, `${refitted} exact fits compared`);
  // Beyond the page's levels, and on a cut by tolerance no count gives, none is listed; a cut by
  // tolerance that is a level by count lists that level's.
  const beyond = await page.evaluate(async () => {
    const viewer = await window.primseg.ready;
    viewer.setClusters(101);
    const shown = { relations: viewer.currentRelations(), summary: document.getElementById('relations-summary').textContent };
    const byTolerance = [];
    for (const tolerance of [1e-4, 3e-4, 1e-3, 3e-3, 1e-2]) {
      viewer.setTolerance(tolerance * viewer.header.bboxDiagonal);
      const K = viewer.cut.size, relations = viewer.currentRelations(), countCut = viewer.tree.isCountCut(viewer.cut);
      viewer.setClusters(K);
      byTolerance.push({ K, countCut, relations, byCount: viewer.currentRelations() });
    }
    return { ...shown, byTolerance };
  });
  assert.equal(beyond.relations, null);
  assert.match(beyond.summary, /none listed beyond 100 clusters/);
  for (const { K, countCut, relations, byCount } of beyond.byTolerance) {
    if (K > 100) continue;
    assert.deepEqual(relations, countCut ? byCount : null, `tolerance level of ${K} clusters`);
  }
  assert.deepEqual(errors, []);
  await page.close();
});

test('couplingdown --regularize: its faces cut apart by holes are listed as coplanar sets, as cut --regularize finds them', async () => {
  execFileSync('tar', ['xzf', '/usr/share/doc/libcgal-dev/data.tar.gz', '-C', work, 'data/meshes/couplingdown.off']);
  const mesh = join(work, 'data/meshes/couplingdown.off'), tree = join(work, 'couplingdown.tree');
  const html = join(work, 'couplingdown-relations.html');
  primseg('segment', mesh, '--tree', tree, '--quiet');
  primseg('view', mesh, '--tree', tree, '--clusters', '30', '--regularize', '-o', html, '--quiet');
  const labelsFile = join(work, 'c.labels'), jsonFile = join(work, 'c.json');
  primseg('cut', tree, '--clusters', '30', '--regularize', '--labels', labelsFile, '--json', jsonFile, '--quiet');
  const cliLabels = readLabels(labelsFile), cli = JSON.parse(readFileSync(jsonFile, 'utf8'));
  const { page, errors } = await openViewer(browser, html);
  const shown = await page.evaluate(async () => {
    const viewer = await window.primseg.ready;
    viewer.setClusters(30);
    return { labels: viewer.labels(), relations: viewer.currentRelations(),
      rows: Array.from(document.querySelectorAll('#relations .relation'), (row) => ({ text: row.textContent, title: row.title })) };
  });
  const cliOf = new Map();
  shown.labels.forEach((p, f) => cliOf.set(p, cliLabels[f]));
  const relations = shown.relations.map((r) => ({ ...r, clusters: r.clusters.map((id) => cliOf.get(id)).sort((a, b) => a - b),
    ...(r.orthogonal_to ? { orthogonal_to: r.orthogonal_to.map((id) => cliOf.get(id)).sort((a, b) => a - b) } : {}) }));
  assert.deepEqual(relations, cli.relations);
  const coplanar = shown.rows.filter((row) => row.text.startsWith('coplanar: '));
  assert.equal(coplanar.length, cli.relations.filter((r) => r.kind === 'coplanar').length);
  assert.ok(coplanar.length >= 2, `${coplanar.length} coplanar sets listed`);
  for (const row of coplanar) assert.match(row.title, /one plane/);
  assert.deepEqual(errors, []);
  await page.close();
});

test('fandisk --regularize: a relation under the pointer, or clicked, leaves only its clusters in colour', async () => {
  const html = join(work, 'fandisk-relations.html');
  const { page, errors } = await openViewer(browser, html, { test: true, width: 640, height: 480 });
  const all = await drawnClusters(page);
  const relations = await page.evaluate(async () => (await window.primseg.ready).levelRelations
    .map(({ kind, members, others }) => ({ kind, members: [...members, ...others] })));
  assert.ok(relations.length >= 4);
  for (const [i, relation] of relations.entries()) {
    if (i > 0 && relation.kind === relations[i - 1].kind) continue;  // one of each kind
    await page.click(`#relations .relation[data-index="${i}"]`);
    const drawn = await drawnClusters(page);
    const members = new Set(relation.members);
    assert.deepEqual(drawn, new Set(relation.members.filter((c) => all.has(c))), `${relation.kind} ${i}: only its clusters in colour`);
    assert.ok(drawn.size >= 1 && [...drawn].every((c) => members.has(c)));
    if (relation.kind === 'coaxial') {
      // Its axis is drawn: a line on every cylinder's axis, through every sphere's centre.
      const { line, primitives } = await page.evaluate(async (members) => {
        const viewer = await window.primseg.ready;
        return { line: viewer.axisLine, primitives: members.map((c) => viewer.primitiveOf(c)) };
      }, relation.members);
      for (const { type, point, axis } of primitives) {
        if (type === 2) {  // a sphere: its centre is on the line
          const along = line[1].map((x, a) => x - line[0][a]), d = point.map((x, a) => x - line[0][a]);
          const t = (d[0] * along[0] + d[1] * along[1] + d[2] * along[2]) / (along[0] ** 2 + along[1] ** 2 + along[2] ** 2);
          assert.ok(Math.hypot(...d.map((x, a) => x - t * along[a])) < 1e-9, 'a sphere of the set is centred on the line');
          continue;
        }
        for (const end of line) {
          const d = end.map((x, a) => x - point[a]), t = d[0] * axis[0] + d[1] * axis[1] + d[2] * axis[2];
          assert.ok(Math.hypot(...d.map((x, a) => x - t * axis[a])) < 1e-9, 'the axis line is on each cylinder\'s axis');
        }
      }
      assert.ok(Math.hypot(...line[0].map((x, a) => x - line[1][a])) > 0.05, 'the line spans the members');
    }
    await page.click(`#relations .relation[data-index="${i}"]`);  // unpinned
  }
  assert.equal(await page.evaluate(async () => (await window.primseg.ready).axisLine), null);
  await page.mouse.move(5, 470);
  assert.deepEqual(await drawnClusters(page), all, 'every cluster in colour again');
  // Pointing at a row emphasises its relation without a click.
  await page.hover('#relations .relation[data-index="0"]');
  assert.deepEqual(await drawnClusters(page), new Set(relations[0].members.filter((c) => all.has(c))));
  assert.deepEqual(errors, []);
  await page.close();

  // A picture for the eye: the fitted primitives, made exact, and a coaxial set pinned.
  const shown = await openViewer(browser, html, { width: 1100, height: 700 });
  await shown.page.check('#show-primitives');
  const coaxial = relations.findIndex((r) => r.kind === 'coaxial');
  await shown.page.click(`#relations .relation[data-index="${coaxial}"]`);
  await shown.page.screenshot({ path: join(artifacts, 'fandisk-relations.png') });
  assert.deepEqual(shown.errors, []);
  await shown.page.close();
});

test('a page without --regularize shows no relations', async () => {
  const { page, errors } = await openViewer(browser, join(work, 'fandisk.html'));
  const state = await page.evaluate(async () => {
    const viewer = await window.primseg.ready;
    return { relations: viewer.currentRelations(), row: getComputedStyle(document.getElementById('relations-row')).display };
  });
  assert.deepEqual(state, { relations: null, row: 'none' });
  assert.deepEqual(errors, []);
  await page.close();
});

test('the page is the same bytes from the mesh alone or with its tree', () => {
  const html = join(work, 'again.html');
  primseg('view', fandisk, '--clusters', '27', '-o', html, '--quiet');
  assert.ok(readFileSync(html).equals(readFileSync(join(work, 'fandisk.html'))));
  // The tree piped on standard input ('-').
  const piped = join(work, 'piped.html');
  execFileSync(cli, ['view', fandisk, '--tree', '-', '--clusters', '27', '-o', piped, '--quiet'],
    { input: readFileSync(join(work, 'fandisk.tree')) });
  assert.ok(readFileSync(piped).equals(readFileSync(join(work, 'fandisk.html'))));
});

test('bad input: a clear error and exit status 1', () => {
  const cases = [
    [['view', join(work, 'missing.off'), '-o', join(work, 'x.html')], /cannot|missing/],
    [['view', fandisk, '--clusters', '0', '-o', join(work, 'x.html')], /--clusters/],
    [['view', join(work, 'box.off'), '--tree', join(work, 'fandisk.tree'), '-o', join(work, 'x.html')], /was not built from/],
    [['view', fandisk], /output/i],
    [['view', fandisk, '--skeleton-clusters', 'many', '-o', join(work, 'x.html')], /--clusters: 'many'/],
    [['view', fandisk, '--skeleton', '--band', '-1', '-o', join(work, 'x.html')], /--band/],
    [['view', fandisk, '--regularize-clusters', '0', '-o', join(work, 'x.html')], /--regularize-clusters/],
    [['view', fandisk, '--regularize-clusters', '16386', '-o', join(work, 'x.html')], /--regularize-clusters/],
    // --max-faces and --max-memory, as segment has them (tests/cli/batch_test.cpp, without viewer).
    [['view', fandisk, '--max-faces', '12945', '-o', join(work, 'x.html')],
      /the mesh has 12946 faces, more than --max-faces 12945/],
    [['view', fandisk, '--max-memory', '16M', '-o', join(work, 'x.html')],
      /the mesh has 12946 faces, which need about \d+ bytes, more than --max-memory 16777216/],
  ];
  const both = ['view', '-', '--tree', '-', '-o', join(work, 'x.html')];
  cases.push([both, /only one of MESH and --tree can be standard input/]);
  for (const [args, message] of cases) {
    const run = spawnSync(cli, args, { encoding: 'utf8', input: '' });
    assert.equal(run.status, 1, args.join(' ') + ': ' + run.stderr);
    assert.match(run.stderr, message);
  }
});
