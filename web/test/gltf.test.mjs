// `primseg skeleton --gltf`: the rigged mesh as binary glTF, checked by two readers primseg does not
// write: the Khronos glTF validator (no error, no warning) and three.js's GLTFLoader, whose
// skinning, with the pose's rotations set on the bones' nodes, must move every vertex where
// `primseg deform` moves it (to float32 round-off). Runs in Node: no browser needed.
// PRIMSEG: the CLI; PRIMSEG_STICK_FIGURE: the generated stick figure's writer.
import { before, test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join, resolve } from 'node:path';
import { fileURLToPath } from 'node:url';
import * as THREE from 'three';
import { GLTFLoader } from 'three/addons/loaders/GLTFLoader.js';
import validator from 'gltf-validator';
import { figurePose, largestDifference, readOffPositions } from './meshes.mjs';

const here = dirname(fileURLToPath(import.meta.url));
const cli = resolve(process.env.PRIMSEG ?? join(here, '../../build/primseg'));
const figureWriter = resolve(process.env.PRIMSEG_STICK_FIGURE ?? join(here, '../../build/tests/primseg_write_stick_figure'));
const work = mkdtempSync(join(tmpdir(), 'primseg-web-gltf-'));
const file = (name) => join(work, name);
const primseg = (...args) => execFileSync(cli, args, { encoding: 'utf8', stdio: ['ignore', 'pipe', 'pipe'] });

async function loadGltf(path) {
  const bytes = readFileSync(path);
  const buffer = bytes.buffer.slice(bytes.byteOffset, bytes.byteOffset + bytes.byteLength);
  const gltf = await new GLTFLoader().parseAsync(buffer, '');
  let mesh = null;
  gltf.scene.traverse((object) => { if (object.isSkinnedMesh) mesh = object; });
  assert.ok(mesh, 'the file has a skinned mesh');
  return { gltf, mesh };
}

/** three.js's skinned positions of every vertex, flat, after the scene's transforms update. */
function skinnedPositions({ gltf, mesh }) {
  gltf.scene.updateMatrixWorld(true);
  mesh.skeleton.update();
  const count = mesh.geometry.attributes.position.count, out = [], v = new THREE.Vector3();
  for (let i = 0; i < count; ++i) {
    v.fromBufferAttribute(mesh.geometry.attributes.position, i);
    mesh.applyBoneTransform(i, v);
    out.push(v.x, v.y, v.z);
  }
  return out;
}

// The stick figure of the skeleton tests at K = 8, with cylinders and spheres.
let skeleton, rest, size;
before(() => {
  if (!existsSync(figureWriter))
    throw new Error(`no ${figureWriter}: build the target primseg_write_stick_figure (or set PRIMSEG_STICK_FIGURE)`);
  execFileSync(figureWriter, [file('figure.off')]);
  primseg('skeleton', file('figure.off'), '--clusters', '8', '--primitives', 'cylinder,sphere',
    '-o', file('skeleton.json'), '--gltf', file('figure.glb'), '--quiet');
  skeleton = JSON.parse(readFileSync(file('skeleton.json'), 'utf8'));
  rest = readOffPositions(file('figure.off'));
  size = Math.max(...rest.map(Math.abs));
});

test('the Khronos glTF validator finds no error and no warning', async () => {
  const report = await validator.validateBytes(new Uint8Array(readFileSync(file('figure.glb'))));
  assert.deepEqual(report.issues.messages.filter((m) => m.severity <= 1), []);
  assert.equal(report.issues.numErrors, 0);
  assert.equal(report.issues.numWarnings, 0);
  assert.equal(report.info.hasSkins, true);
});

test('three.js reads one bone per cluster, an end per virtual joint, and the rest pose in place', async () => {
  const loaded = await loadGltf(file('figure.glb'));
  const bones = loaded.mesh.skeleton.bones;
  const ends = skeleton.joints.filter((j) => j.kind === 'virtual');
  assert.equal(bones.length, skeleton.cluster_count + ends.length);
  skeleton.bones.forEach((bone, b) => {
    assert.equal(bones[b].name, `bone_${b}`);
    assert.equal(bones[b].userData.bone, b);
  });
  ends.forEach((joint, e) => {
    const end = bones[skeleton.cluster_count + e];
    assert.equal(end.userData.joint, joint.id);
    end.updateMatrixWorld(true);
    const at = new THREE.Vector3().setFromMatrixPosition(end.matrixWorld);
    assert.ok(at.distanceTo(new THREE.Vector3(...joint.position)) <= 1e-6 * size);
  });
  const difference = largestDifference(skinnedPositions(loaded), rest);
  assert.ok(difference <= 1e-6 * size, `rest pose moved by ${difference}`);
});

test('posing the bones in three.js moves every vertex where primseg deform does', async () => {
  // Nested along the left arm (shoulder then elbow), oblique axes, and a hip.
  const rotations = figurePose(skeleton);
  writeFileSync(file('pose.json'), JSON.stringify({ rotations }));
  primseg('deform', file('figure.off'), file('skeleton.json'), file('pose.json'), '-o', file('posed.off'), '--quiet');
  const expected = readOffPositions(file('posed.off'));

  const loaded = await loadGltf(file('figure.glb'));
  const bones = loaded.mesh.skeleton.bones;
  for (const { joint, axis, degrees } of rotations) {
    // The bone that hangs from the joint: its node's extras name the joint.
    const hanging = bones.filter((bone) => bone.userData.joint === joint && bone.userData.bone !== undefined);
    assert.equal(hanging.length, 1, `one bone hangs from joint ${joint}`);
    assert.equal(hanging[0].userData.joint_kind, 'sensitive');
    hanging[0].quaternion.setFromAxisAngle(new THREE.Vector3(...axis).normalize(), (degrees * Math.PI) / 180);
  }
  const posed = skinnedPositions(loaded);
  assert.ok(largestDifference(expected, rest) > 1, 'the pose moves the limbs');
  const difference = largestDifference(posed, expected);
  console.log(`# three.js vs primseg deform: largest coordinate difference ${difference.toExponential(2)}`);
  assert.ok(difference <= 1e-5 * size, `three.js and primseg deform differ by ${difference}`);
});
