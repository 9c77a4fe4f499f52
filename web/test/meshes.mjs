// Test meshes written as OFF files: generated here, so that the tests need no data download.
import assert from 'node:assert/strict';
import { readFileSync, writeFileSync } from 'node:fs';

function writeOff(path, vertices, triangles) {
  const lines = ['OFF', `${vertices.length} ${triangles.length} 0`];
  for (const v of vertices) lines.push(v.join(' '));
  for (const t of triangles) lines.push('3 ' + t.join(' '));
  writeFileSync(path, lines.join('\n') + '\n');
}

/** A box of size 2 x 1.5 x 1 with every side an n x n grid: 6 planes, 12 n^2 triangles. */
export function writeGridBox(path, n) {
  const vertices = [], triangles = [], index = new Map();
  const vertex = (p) => {
    const key = p.join(',');
    if (!index.has(key)) {
      index.set(key, vertices.length);
      vertices.push(p);
    }
    return index.get(key);
  };
  const size = [2, 1.5, 1];
  for (let axis = 0; axis < 3; ++axis)
    for (const side of [0, 1]) {
      const [u, v] = [(axis + 1) % 3, (axis + 2) % 3];
      const point = (i, j) => {
        const p = [0, 0, 0];
        p[axis] = side * size[axis];
        p[u] = (i / n) * size[u];
        p[v] = (j / n) * size[v];
        return vertex(p);
      };
      for (let i = 0; i < n; ++i)
        for (let j = 0; j < n; ++j) {
          const [a, b, c, d] = [point(i, j), point(i + 1, j), point(i + 1, j + 1), point(i, j + 1)];
          // Outward orientation: flip on the low side.
          if (side) triangles.push([a, b, c], [a, c, d]);
          else triangles.push([a, c, b], [a, d, c]);
        }
    }
  writeOff(path, vertices, triangles);
  return triangles.length;
}

/** A wavy torus of 2 * rows * columns triangles (a big, curved test surface). */
export function writeWavyTorus(path, rows, columns) {
  const vertices = [], triangles = [];
  for (let i = 0; i < rows; ++i)
    for (let j = 0; j < columns; ++j) {
      const phi = (2 * Math.PI * i) / rows, psi = (2 * Math.PI * j) / columns;
      const r = 1 + 0.05 * Math.sin(7 * phi) * Math.cos(3 * psi);
      const ring = 3 + r * Math.cos(psi);
      vertices.push([(ring * Math.cos(phi)).toFixed(6), (ring * Math.sin(phi)).toFixed(6), (r * Math.sin(psi)).toFixed(6)]);
    }
  const at = (i, j) => (i % rows) * columns + (j % columns);
  for (let i = 0; i < rows; ++i)
    for (let j = 0; j < columns; ++j)
      triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)], [at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
  writeOff(path, vertices, triangles);
  return triangles.length;
}

/** Vertex positions of an OFF file, flat. */
export function readOffPositions(path) {
  const words = readFileSync(path, 'utf8').split('\n').filter((line) => !line.startsWith('#'))
    .join(' ').trim().split(/\s+/);
  assert.equal(words[0], 'OFF');
  const vertices = Number(words[1]);
  return words.slice(4, 4 + 3 * vertices).map(Number);
}

/** Largest difference between two flat position arrays. */
export function largestDifference(a, b) {
  assert.equal(a.length, b.length);
  let largest = 0;
  for (let i = 0; i < a.length; ++i) largest = Math.max(largest, Math.abs(a[i] - b[i]));
  return largest;
}

/** The id of the joint of a skeleton file (primseg skeleton -o, parsed) nearest a point. */
export function nearestJoint(skeleton, point) {
  let best = null;
  for (const joint of skeleton.joints) {
    const d = Math.hypot(...joint.position.map((x, a) => x - point[a]));
    if (!best || d < best.d) best = { id: joint.id, d };
  }
  return best.id;
}

/** The stick figure's test pose (tests/support/stick_figure.hpp at K = 8): the left shoulder and
 *  elbow nested along the arm, the right elbow and the right hip, about oblique axes. */
export function figurePose(skeleton) {
  const at = (point) => nearestJoint(skeleton, point);
  return [
    { joint: at([-1, 0, 3.2]), axis: [0.2, 1, 0.3], degrees: 35 },
    { joint: at([-2.4, 0, 3.2]), axis: [0, 1, 0], degrees: -50 },
    { joint: at([2.4, 0, 3.2]), axis: [0.5, -1, 2], degrees: 70.5 },
    { joint: at([1, 0, 1.2]), axis: [1, 1, 0], degrees: 20 },
  ];
}

/** A book: n triangles on one spine edge (vertices 0 and 1), page i through vertex i + 2. */
export function writeBook(path, n) {
  const vertices = [[0, 0, 0], [0, 0, 1]], triangles = [];
  for (let i = 0; i < n; ++i) {
    const angle = (2 * Math.PI * i) / n;
    vertices.push([Math.cos(angle), Math.sin(angle), 0.5]);
    triangles.push([0, 1, i + 2]);
  }
  writeOff(path, vertices, triangles);
}
