// Figures of `primseg view` pages (printed, not asserted: the machine is shared and noisy):
// page size, load time in headless chromium (median of 3 loads) and slider step time (median of
// 20 steps between log-spaced levels: the page's work, a cut and a recolouring, then apart the
// time until the frame is drawn, which headless chromium does in software: SwiftShader).
//
// Usage: PRIMSEG=path/to/primseg node bench/viewer-bench.mjs MESH[,TREE]|PAGE.html...
//        (a mesh named "torus1m" is generated: 1,000,000 triangles; with a TREE saved by
//        primseg segment --tree, the hierarchy is read instead of built; a PAGE.html already
//        written by primseg view is measured as it is)
import { execFileSync } from 'node:child_process';
import { mkdtempSync, statSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { basename, join, resolve } from 'node:path';
import { launchBrowser, openViewer } from '../test/browser.mjs';
import { writeWavyTorus } from '../test/meshes.mjs';

const cli = resolve(process.env.PRIMSEG ?? '../build/primseg');
const work = mkdtempSync(join(tmpdir(), 'primseg-web-bench-'));
const median = (values) => [...values].sort((a, b) => a - b)[Math.floor(values.length / 2)];

const browser = await launchBrowser();
for (const arg of process.argv.slice(2)) {
  let [mesh, tree] = arg.split(',');
  if (mesh === 'torus1m') {
    mesh = join(work, 'torus1m.off');
    writeWavyTorus(mesh, 1000, 500);
  }
  const given = mesh.endsWith('.html');
  const html = given ? resolve(mesh) : join(work, basename(mesh) + '.html');
  const start = Date.now();
  if (!given) execFileSync(cli, ['view', mesh, ...(tree ? ['--tree', tree] : []), '-o', html, '--quiet']);
  const viewSeconds = (Date.now() - start) / 1000;
  const loads = [];
  let steps = null;
  for (let run = 0; run < 3; ++run) {
    const { page, errors, loadMs, wallMs } = await openViewer(browser, html);
    if (errors.length) throw new Error(`${mesh}: console errors: ${errors.join('; ')}`);
    loads.push({ loadMs, wallMs });
    if (run === 0)
      steps = await page.evaluate(async () => {
        const viewer = await window.primseg.ready;
        const F = viewer.tree.faceCount, page = [], frame = [];
        for (let i = 0; i < 20; ++i) {
          const K = Math.round(Math.exp(((i % 10) / 10) * Math.log(F))) + (i >= 10 ? 1 : 0);
          viewer.setClusters(K);
          page.push(viewer.stepTimes[viewer.stepTimes.length - 1]);
          const start = performance.now();
          const gl = viewer.renderer.getContext(); // reading a pixel waits until the frame is drawn
          gl.readPixels(0, 0, 1, 1, gl.RGBA, gl.UNSIGNED_BYTE, new Uint8Array(4));
          frame.push(performance.now() - start);
        }
        return { page, frame };
      });
    await page.close();
  }
  console.log(`${basename(mesh)}: page ${(statSync(html).size / 1e6).toFixed(1)} MB (primseg view ${viewSeconds.toFixed(1)} s), ` +
    `load ${(median(loads.map((l) => l.loadMs)) / 1000).toFixed(2)} s in the page ` +
    `(${(median(loads.map((l) => l.wallMs)) / 1000).toFixed(2)} s from navigation), ` +
    `slider step median ${median(steps.page).toFixed(1)} ms (max ${Math.max(...steps.page).toFixed(1)} ms) ` +
    `in the page, then the frame (software GL here) ${median(steps.frame).toFixed(0)} ms`);
}
await browser.close();
