// The skeleton overlay of `primseg view --skeleton`, in a real browser: the page's skeleton is
// the one `primseg skeleton` extracts, a pose applied in the page moves every vertex where
// `primseg deform` moves it (to 1e-9), dragging a joint poses the mesh, and locked joints do not
// move. On the generated stick figure of the C++ skeleton tests (tests/support/stick_figure.hpp,
// written by tests/tools/write_stick_figure.cpp).
// PRIMSEG: the CLI; PRIMSEG_STICK_FIGURE: the figure's writer; PRIMSEG_WEB_ARTIFACTS: screenshots.
import { after, before, test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, mkdirSync, mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import { launchBrowser, openViewer } from './browser.mjs';
import { figurePose, largestDifference, nearestJoint, readOffPositions } from './meshes.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const cli = resolve(process.env.PRIMSEG ?? join(here, '../../build/primseg'));
const figureWriter = resolve(process.env.PRIMSEG_STICK_FIGURE ?? join(here, '../../build/tests/primseg_write_stick_figure'));
const artifacts = resolve(process.env.PRIMSEG_WEB_ARTIFACTS ?? join(tmpdir(), 'primseg-web-artifacts'));
const work = mkdtempSync(join(tmpdir(), 'primseg-web-skeleton-'));
mkdirSync(artifacts, { recursive: true });

const primseg = (...args) => execFileSync(cli, args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });
const file = (name) => join(work, name);
const SENSITIVE = 0, LOCKED = 1, VIRTUAL = 2;
const KINDS = ['sensitive', 'locked', 'virtual'];

// The figure's skeleton at K = 8 (torso, head, two upper arms, two forearms, two legs), from
// primseg skeleton and in the page, with cylinders and spheres as in the C++ skeleton tests.
const K = '8', PRIMITIVES = 'cylinder,sphere';
let browser, skeleton, rest;
before(async () => {
  if (!existsSync(figureWriter))
    throw new Error(`no ${figureWriter}: build the target primseg_write_stick_figure (or set PRIMSEG_STICK_FIGURE)`);
  browser = await launchBrowser();
  execFileSync(figureWriter, [file('figure.off')]);
  primseg('skeleton', file('figure.off'), '--clusters', K, '--primitives', PRIMITIVES, '-o', file('skeleton.json'), '--quiet');
  skeleton = JSON.parse(readFileSync(file('skeleton.json'), 'utf8'));
  primseg('view', file('figure.off'), '--primitives', PRIMITIVES, '--clusters', K, '--skeleton', '-o', file('figure.html'), '--quiet');
  rest = readOffPositions(file('figure.off'));
});
after(async () => browser?.close());

/** Opens the figure's page, seen from the front (-y) with z up, the whole figure in view. */
async function openFigure({ file: html = file('figure.html') } = {}) {
  const opened = await openViewer(browser, html, { width: 1200, height: 900 });
  await opened.page.evaluate(async () => {
    const viewer = await window.primseg.ready;
    const center = viewer.geometry.boundingSphere.center;
    viewer.camera.up.set(0, 0, 1);
    viewer.camera.position.copy(center).add({ x: 0, y: -3.2 * viewer.radius, z: 0 });
    viewer.controls.target.copy(center);
    viewer.controls.update();
    viewer.render();
  });
  return opened;
}

/** Asserts that the page's skeleton is `expected` (a skeleton file), and that it draws its visible joints. */
async function assertPageCarries(page, expected) {
  const shown = await page.evaluate(async () => {
    const viewer = await window.primseg.ready, s = viewer.skeleton.skeleton;
    const joints = [];
    for (let j = 0; j < s.jointCount; ++j)
      joints.push({ id: j, position: s.jointPosition(j), kind: s.kind(j), visible: s.s.jointVisible[j] === 1, bones: Array.from(s.jointBones(j)) });
    const bones = [];
    for (let b = 0; b < s.boneCount; ++b) bones.push({ joints: Array.from(s.boneJoints(b)), visible: s.s.boneVisible[b] === 1 });
    return { joints, bones, drawnJoints: viewer.skeleton.jointMeshes.map((m) => m.userData.joint),
      faceLabels: Array.from(s.s.faceLabels), summary: document.getElementById('skeleton-summary').textContent };
  });
  assert.equal(shown.bones.length, expected.cluster_count);
  assert.deepEqual(shown.faceLabels, expected.face_labels);
  assert.equal(shown.joints.length, expected.joints.length);
  for (const [i, joint] of expected.joints.entries()) {
    assert.deepEqual(shown.joints[i].position, joint.position);
    assert.equal(KINDS[shown.joints[i].kind], joint.kind);
    assert.equal(shown.joints[i].visible, joint.visible);
    assert.deepEqual(shown.joints[i].bones, joint.bones);
  }
  expected.bones.forEach((bone, b) => assert.deepEqual(shown.bones[b], { joints: bone.joints, visible: bone.visible }));
  // Hidden joints are not drawn; every visible one is.
  assert.deepEqual(shown.drawnJoints, expected.joints.filter((j) => j.visible).map((j) => j.id));
  assert.match(shown.summary, new RegExp(`^${expected.cluster_count} bones`));
}

test('the page carries the skeleton primseg skeleton extracts, and draws its visible parts', async () => {
  const { page, errors } = await openFigure();
  await assertPageCarries(page, skeleton);
  await page.screenshot({ path: join(artifacts, 'figure-skeleton.png') });
  assert.deepEqual(errors, []);
  await page.close();
});

test('a pose applied in the page moves every vertex where primseg deform moves it, to 1e-9', async () => {
  // Elbows, a shoulder and a hip, about oblique axes: rotations nested along the arm.
  const rotations = figurePose(skeleton);
  for (const { joint } of rotations) assert.equal(skeleton.joints[joint].kind, 'sensitive');
  const pose = { rotations };
  writeFileSync(file('pose.json'), JSON.stringify(pose));
  primseg('deform', file('figure.off'), file('skeleton.json'), file('pose.json'), '-o', file('posed.off'), '--quiet');
  const expected = readOffPositions(file('posed.off'));

  const { page, errors } = await openFigure();
  const posed = await page.evaluate(async (p) => {
    await window.primseg.setPose(p);
    return window.primseg.deformedPositions();
  }, pose);
  assert.ok(largestDifference(expected, rest) > 1, 'the pose moves the limbs');
  const difference = largestDifference(posed, expected);
  console.log(`# page vs primseg deform: largest coordinate difference ${difference.toExponential(2)}`);
  assert.ok(difference <= 1e-9, `largest difference ${difference}`);
  // What is drawn is the posed mesh (float32, relative to the centre).
  const drawn = await page.evaluate(async () => {
    const viewer = await window.primseg.ready;
    const corners = viewer.geometry.getAttribute('position').array, t = viewer.data.triangles, c = viewer.header.center;
    const positions = new Float64Array(3 * viewer.header.vertices);
    viewer.drawOrder.forEach((triangle, slot) => {
      for (let k = 0; k < 3; ++k)
        for (let a = 0; a < 3; ++a) positions[3 * t[3 * triangle + k] + a] = corners[9 * slot + 3 * k + a] + c[a];
    });
    return Array.from(positions);
  });
  assert.ok(largestDifference(drawn, expected) < 1e-5);
  // The border lines follow the posed mesh: each end at its vertex's posed position.
  await page.check('#show-borders');
  const lineEnds = await page.evaluate(async () => {
    const viewer = await window.primseg.ready, c = viewer.header.center;
    const ends = viewer.borderLines.lines.geometry.getAttribute('position').array;
    return viewer.borderLines.borderEdges().flatMap((edge, i) =>
      edge.map((v, end) => ({ v, p: [0, 1, 2].map((a) => ends[6 * i + 3 * end + a] + c[a]) })));
  });
  assert.ok(lineEnds.length > 0);
  for (const { v, p } of lineEnds)
    assert.ok(largestDifference(p, expected.slice(3 * v, 3 * v + 3)) < 1e-5, `border line end at vertex ${v}`);
  await page.screenshot({ path: join(artifacts, 'figure-posed.png') });
  // A pose primseg refuses is refused in the page too, and changes nothing.
  const locked = skeleton.joints.find((j) => j.kind !== 'sensitive');
  const refusal = await page.evaluate(async (joint) => {
    try {
      await window.primseg.setPose({ rotations: [{ joint, axis: [0, 0, 1], degrees: 10 }] });
      return null;
    } catch (error) {
      return String(error.message);
    }
  }, locked.id);
  assert.match(refusal, /only sensitive joints rotate/);
  assert.ok(largestDifference(await page.evaluate(() => window.primseg.deformedPositions()), expected) <= 1e-9);
  assert.deepEqual(errors, []);
  await page.close();
});

/** Drags the mouse from a joint by (dx, dy) pixels, in steps. */
async function dragJoint(page, joint, dx, dy) {
  const [x, y] = await page.evaluate(async (j) => (await window.primseg.ready).skeleton.jointOnScreen(j), joint);
  await page.mouse.move(x, y);
  await page.mouse.down();
  for (let step = 1; step <= 8; ++step) await page.mouse.move(x + (dx * step) / 8, y + (dy * step) / 8);
  await page.mouse.up();
}

test('dragging joints poses the mesh live, as primseg deform poses it', async () => {
  const { page, errors } = await openFigure();
  const elbow = nearestJoint(skeleton, [2.4, 0, 3.2]);
  const hand = skeleton.joints.find((j) => j.kind === 'virtual' && j.position[0] > 2 && j.position[2] > 1.5).id;
  // The right forearm: dragging its free end (the hand) turns it about the elbow, so that the hand
  // follows the pointer; then dragging the elbow turns the whole forearm again.
  const before = await page.evaluate(async (j) => (await window.primseg.ready).skeleton.jointOnScreen(j), hand);
  await dragJoint(page, hand, 60, -90);
  let pose = await page.evaluate(() => window.primseg.pose());
  assert.equal(pose.rotations.length, 1);
  assert.equal(pose.rotations[0].joint, elbow, 'the hand turns its bone about the elbow');
  // Seen from -y, the axis is the viewing direction (towards the viewer: -y); the hand went up,
  // counter-clockwise on the screen about the elbow on the right: a positive angle about -y.
  const [ax, ay, az] = pose.rotations[0].axis, degrees = pose.rotations[0].degrees;
  // (To 1e-5: the orbit controls keep the camera 1e-6 radians off their pole, here the y axis.)
  assert.ok(Math.abs(ax) < 1e-5 && Math.abs(az) < 1e-5 && Math.abs(Math.abs(ay) - 1) < 1e-5, `axis ${pose.rotations[0].axis}`);
  assert.ok(Math.sign(ay) * -degrees > 10, `angle ${degrees} about ${ay}`);
  const after = await page.evaluate(async (j) => (await window.primseg.ready).skeleton.jointOnScreen(j), hand);
  assert.ok(Math.hypot(after[0] - before[0], after[1] - before[1]) > 40, 'the hand moved on the screen');
  await dragJoint(page, elbow, 0, 80);
  await page.screenshot({ path: join(artifacts, 'figure-dragged.png') });
  pose = await page.evaluate(() => window.primseg.pose());
  assert.equal(pose.rotations.length, 1, 'the elbow turned further');
  // The dragged pose, saved by the page's button and run through primseg deform, gives the page's
  // vertices.
  const [download] = await Promise.all([page.waitForEvent('download'), page.click('#save-pose')]);
  assert.equal(download.suggestedFilename(), 'pose.json');
  await download.saveAs(file('dragged.json'));
  assert.deepEqual(JSON.parse(readFileSync(file('dragged.json'), 'utf8')), pose);
  assert.match(await page.textContent('#status'), /^pose\.json saved: 1 joint turned/);
  primseg('deform', file('figure.off'), file('skeleton.json'), file('dragged.json'), '-o', file('dragged.off'), '--quiet');
  const page_positions = await page.evaluate(() => window.primseg.deformedPositions());
  // The pose file goes through JSON (17 significant digits): the angle is read back rounded.
  assert.ok(largestDifference(page_positions, readOffPositions(file('dragged.off'))) <= 1e-9);
  assert.ok(largestDifference(page_positions, rest) > 0.3, 'the drags moved the forearm');
  // Reset pose: back to rest exactly.
  await page.click('#reset-pose');
  assert.equal(largestDifference(await page.evaluate(() => window.primseg.deformedPositions()), rest), 0);
  assert.deepEqual(errors, []);
  await page.close();
});

test('at 9 clusters: a locked joint is drawn but cannot be dragged, hidden bones are not drawn', async () => {
  // The torso splits: a hub of three clusters (a locked joint), two of whose bones are hidden.
  primseg('skeleton', file('figure.off'), '--clusters', '9', '--primitives', PRIMITIVES, '-o', file('skeleton9.json'), '--quiet');
  const skeleton9 = JSON.parse(readFileSync(file('skeleton9.json'), 'utf8'));
  primseg('view', file('figure.off'), '--primitives', PRIMITIVES, '--clusters', K, '--skeleton-clusters', '9', '-o', file('figure9.html'), '--quiet');
  const locked = skeleton9.joints.find((j) => j.kind === 'locked' && j.visible);
  assert.ok(locked, 'the skeleton has a visible locked joint');
  const hidden = skeleton9.bones.filter((b) => !b.visible).map((b) => b.id);
  assert.ok(hidden.length > 0, 'the skeleton has hidden bones');
  const { page, errors } = await openFigure({ file: file('figure9.html') });
  const drawn = await page.evaluate(async () => {
    const overlay = (await window.primseg.ready).skeleton;
    return { bones: [...new Set(overlay.sticks.map((s) => s.bone))].sort((a, b) => a - b),
      joints: overlay.jointMeshes.map((m) => m.userData.joint), clusters: overlay.skeleton.boneCount };
  });
  assert.equal(drawn.clusters, 9);
  assert.deepEqual(drawn.bones, skeleton9.bones.filter((b) => b.visible).map((b) => b.id));
  assert.deepEqual(drawn.joints, skeleton9.joints.filter((j) => j.visible).map((j) => j.id));
  await page.screenshot({ path: join(artifacts, 'figure-skeleton-9.png') });
  const camera = () => page.evaluate(async () => (await window.primseg.ready).camera.position.toArray());
  const before = await camera();
  await dragJoint(page, locked.id, 120, 40);
  assert.deepEqual(await page.evaluate(() => window.primseg.pose()), { rotations: [] });
  assert.equal(largestDifference(await page.evaluate(() => window.primseg.deformedPositions()), rest), 0);
  assert.notDeepEqual(await camera(), before, 'the drag orbits the view');
  assert.match(await page.textContent('#status'), /locked: it does not move/);
  assert.deepEqual(errors, []);
  await page.close();
});

test('--joints limbs: the page carries the limb rule\'s skeleton, and a bone the hub hid turns', async () => {
  // At 9 clusters the paper's rule locks a hub and hides two of its bones (the test above); the
  // limb rule frees one of them with a sensitive joint where it is attached.
  const extract = (rule, name) => {
    primseg('skeleton', file('figure.off'), '--clusters', '9', '--primitives', PRIMITIVES, '--joints', rule, '-o', file(name), '--quiet');
    return JSON.parse(readFileSync(file(name), 'utf8'));
  };
  const paper = extract('paper', 'paper9.json'), limbs = extract('limbs', 'limbs9.json');
  const hidden = paper.bones.filter((b) => !b.visible).map((b) => b.id);
  const freed = limbs.joints.find((j) => j.kind === 'sensitive' && j.bones.some((b) => hidden.includes(b)));
  assert.ok(freed, 'a bone the paper\'s hub hid has a sensitive joint');
  primseg('view', file('figure.off'), '--primitives', PRIMITIVES, '--clusters', K, '--skeleton-clusters', '9', '--joints', 'limbs', '-o', file('limbs9.html'), '--quiet');
  const { page, errors } = await openFigure({ file: file('limbs9.html') });
  await assertPageCarries(page, limbs);
  await dragJoint(page, freed.id, 0, 80);
  const pose = await page.evaluate(() => window.primseg.pose());
  assert.equal(pose.rotations.length, 1);
  assert.equal(pose.rotations[0].joint, freed.id);
  assert.ok(largestDifference(await page.evaluate(() => window.primseg.deformedPositions()), rest) > 0.05, 'the limb moved');
  await page.screenshot({ path: join(artifacts, 'figure-skeleton-limbs-9.png') });
  assert.deepEqual(errors, []);
  await page.close();
});
