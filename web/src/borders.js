// The "borders" lines of a level: the mesh edges between faces of different clusters, and the
// mesh's open boundary, drawn over the mesh: what `primseg segment --borders` writes as curves.
// The lines take their ends from the drawn mesh, so they follow a posed skeleton.

import * as THREE from 'three';
import { cross, dot, norm, normal, sub } from './primitives.js';

/** edgeOfSide's entry for a side whose two corners are one vertex: on no edge. */
const NO_EDGE = 0xffffffff;

/**
 * Every mesh edge once: its two vertices, the triangles on it and, for drawing, the corners of
 * its first triangle in the drawn (non-indexed) geometry; and the edge of each triangle side.
 * @param triangles vertex indices, 3 per triangle
 * @param slotOf the geometry slot of each triangle
 */
function meshEdges(triangles, slotOf, vertexCount) {
  const T = triangles.length / 3;
  // Each triangle side (a, b), a != b, filed under its lower vertex: compressed rows.
  const start = new Uint32Array(vertexCount + 1);
  for (let t = 0; t < T; ++t)
    for (let k = 0; k < 3; ++k) {
      const a = triangles[3 * t + k], b = triangles[3 * t + ((k + 1) % 3)];
      if (a !== b) ++start[Math.min(a, b) + 1];
    }
  for (let v = 0; v < vertexCount; ++v) start[v + 1] += start[v];
  const fill = start.slice(0, vertexCount), sides = start[vertexCount];
  const higher = new Uint32Array(sides), side = new Uint32Array(sides); // side: 3 t + k
  for (let t = 0; t < T; ++t)
    for (let k = 0; k < 3; ++k) {
      const a = triangles[3 * t + k], b = triangles[3 * t + ((k + 1) % 3)];
      if (a === b) continue;
      const i = fill[Math.min(a, b)]++;
      higher[i] = Math.max(a, b);
      side[i] = 3 * t + k;
    }
  // Within a row, sides of one edge next to each other (insertion sort: rows are short).
  for (let v = 0; v < vertexCount; ++v)
    for (let i = start[v] + 1; i < start[v + 1]; ++i) {
      const h = higher[i], s = side[i];
      let j = i;
      for (; j > start[v] && (higher[j - 1] > h || (higher[j - 1] === h && side[j - 1] > s)); --j) {
        higher[j] = higher[j - 1];
        side[j] = side[j - 1];
      }
      higher[j] = h;
      side[j] = s;
    }
  const ends = [], sideStart = [0], cornerIndex = [];
  for (let v = 0; v < vertexCount; ++v)
    for (let i = start[v]; i < start[v + 1]; ) {
      let j = i + 1;
      while (j < start[v + 1] && higher[j] === higher[i]) ++j;
      ends.push(v, higher[i]);
      sideStart.push(j);
      // The corners of the edge's lower and higher vertex in its first triangle.
      const t = Math.floor(side[i] / 3), k = side[i] % 3, next = (k + 1) % 3;
      const [low, high] = triangles[3 * t + k] === v ? [k, next] : [next, k];
      cornerIndex.push(3 * (3 * slotOf[t] + low), 3 * (3 * slotOf[t] + high));
      i = j;
    }
  const edgeOfSide = new Uint32Array(3 * T).fill(NO_EDGE); // side 3 t + k: its edge
  for (let e = 0; e + 1 < sideStart.length; ++e)
    for (let i = sideStart[e]; i < sideStart[e + 1]; ++i) edgeOfSide[side[i]] = e;
  return {
    count: ends.length / 2, ends: Uint32Array.from(ends), sideStart: Uint32Array.from(sideStart),
    side, cornerIndex: Uint32Array.from(cornerIndex), edgeOfSide,
  };
}

export class BorderLines {
  /**
   * @param data the page's arrays (triangles, faceOfTriangle, header.vertices)
   * @param geometry the drawn mesh (non-indexed: slot s has corners 3s..3s+2)
   * @param drawOrder the triangle of each slot
   * @param color line colour (0xRRGGBB)
   */
  constructor(data, geometry, drawOrder, color) {
    this.data = data;
    this.geometry = geometry;
    this.drawOrder = drawOrder;
    this.lines = new THREE.LineSegments(new THREE.BufferGeometry(),
      new THREE.LineBasicMaterial({ color }));
    this.lines.renderOrder = 2;
    this.lines.visible = false;
    this.lines.frustumCulled = false;
    this.border = new Uint32Array(0); // edge ids of the current borders
    this.positionVersion = -1;
  }

  get edges() {
    if (!this.edgeTable) {
      const slotOf = new Uint32Array(this.drawOrder.length);
      this.drawOrder.forEach((t, slot) => (slotOf[t] = slot));
      this.edgeTable = meshEdges(this.data.triangles, slotOf, this.data.header.vertices);
    }
    return this.edgeTable;
  }

  /** Shows or hides the lines; `cut` is the current level. */
  setVisible(visible, cut) {
    this.lines.visible = visible;
    if (visible) this.update(cut);
  }

  /** The border edges of `cut` (when shown): an edge of one triangle, or of faces of two clusters. */
  update(cut) {
    if (!this.lines.visible) return;
    const { count, sideStart, side } = this.edges;
    const labels = cut.faceCluster, faceOfTriangle = this.data.faceOfTriangle;
    const clusterOf = (s) => {
      const t = Math.floor(side[s] / 3);
      return labels[faceOfTriangle ? faceOfTriangle[t] : t];
    };
    const border = [];
    for (let e = 0; e < count; ++e) {
      const from = sideStart[e], to = sideStart[e + 1];
      let differ = to - from === 1;
      for (let s = from + 1; s < to && !differ; ++s) differ = clusterOf(s) !== clusterOf(from);
      if (differ) border.push(e);
    }
    this.border = Uint32Array.from(border);
    this.positionVersion = -1;
    this.refresh();
  }

  /** Moves the lines onto the drawn mesh when its positions changed (a pose). */
  refresh() {
    const positions = this.geometry.getAttribute('position');
    if (!this.lines.visible || positions.version === this.positionVersion) return;
    this.positionVersion = positions.version;
    const { cornerIndex } = this.edges, corners = positions.array, B = this.border.length;
    const ends = new Float32Array(6 * B);
    for (let i = 0; i < B; ++i)
      for (let end = 0; end < 2; ++end) {
        const c = cornerIndex[2 * this.border[i] + end];
        ends.set(corners.subarray(c, c + 3), 6 * i + 3 * end);
      }
    const geometry = this.lines.geometry;
    geometry.setAttribute('position', new THREE.BufferAttribute(ends, 3));
    geometry.computeBoundingSphere();
  }

  /**
   * Where cluster c of `cut` meets the others, as primseg's borders (borders.hpp) have it: one
   * entry per neighbouring cluster (-1: the mesh's open boundary) with its edge count, length and
   * mean angle in degrees between the two primitives across the border (null without both
   * primitives or along the open boundary), longest first. O(n log n) in c's n triangles: a
   * click, or every cluster of a fine level in turn, does not scan the whole mesh.
   * @param clusterTriangles the triangles of cluster c (any order)
   * @param primitiveOf (cluster) => primitive in the page's centred coordinates, or null
   */
  clusterBorders(cut, c, clusterTriangles, primitiveOf) {
    const { ends, sideStart, side, edgeOfSide } = this.edges;
    const labels = cut.faceCluster, faceOfTriangle = this.data.faceOfTriangle;
    const positions = this.data.positions, triangles = this.data.triangles;
    const triangleOf = (s) => Math.floor(side[s] / 3);
    const clusterOf = (t) => labels[faceOfTriangle ? faceOfTriangle[t] : t];
    const point = (v) => [positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]];
    const listedNormal = (t) => {
      const [a, b, d] = [0, 1, 2].map((k) => point(triangles[3 * t + k]));
      return cross(sub(b, a), sub(d, a));
    };
    // +1 when triangle t runs from `low` to `high` along the edge, -1 the other way.
    const direction = (t, low, high) => {
      for (let k = 0; k < 3; ++k)
        if (triangles[3 * t + k] === low && triangles[3 * t + ((k + 1) % 3)] === high) return 1;
      return -1;
    };
    const neighbours = new Map(); // cluster -> {edges, length, angleSum, angleWeight}
    const add = (other, length, angle) => {
      const entry = neighbours.get(other) ?? { edges: 0, length: 0, angleSum: 0, angleWeight: 0 };
      entry.edges += 1;
      entry.length += length;
      if (angle !== null) {
        entry.angleSum += length * angle;
        entry.angleWeight += length;
      }
      neighbours.set(other, entry);
    };
    // c's edges in increasing order, each once: the sums below add up in the order of the edge
    // table whatever the order of c's triangles.
    const edges = new Uint32Array(3 * clusterTriangles.length);
    clusterTriangles.forEach((t, i) => edges.set(edgeOfSide.subarray(3 * t, 3 * t + 3), 3 * i));
    edges.sort();
    for (let i = 0; i < edges.length; ++i) {
      const e = edges[i];
      if (e === NO_EDGE || (i > 0 && e === edges[i - 1])) continue;
      const from = sideStart[e], to = sideStart[e + 1];
      const low = ends[2 * e], high = ends[2 * e + 1];
      const a = point(low), b = point(high);
      const length = norm(sub(b, a));
      if (to - from === 1) {
        add(-1, length, null);
        continue;
      }
      // The clusters the dual graph links c to across the edge (its triangles in index order, each
      // linked to the next: sides are sorted by triangle), each by its first link.
      const linked = new Map(); // other cluster -> [c's triangle, theirs]
      for (let s = from; s + 1 < to; ++s) {
        const t = triangleOf(s), u = triangleOf(s + 1);
        const ct = clusterOf(t), cu = clusterOf(u);
        if (ct === cu || (ct !== c && cu !== c)) continue;
        const other = ct === c ? cu : ct;
        if (!linked.has(other)) linked.set(other, ct === c ? [t, u] : [u, t]);
      }
      const ownPrimitive = primitiveOf(c);
      for (const [other, [own, theirs]] of linked) {
        const primitive = primitiveOf(other);
        let angle = null;
        const n1 = listedNormal(own);
        let n2 = listedNormal(theirs);
        if (ownPrimitive && primitive && norm(n1) > 0 && norm(n2) > 0) {
          if (direction(own, low, high) === direction(theirs, low, high)) n2 = n2.map((x) => -x);
          const middle = [(a[0] + b[0]) / 2, (a[1] + b[1]) / 2, (a[2] + b[2]) / 2];
          const oriented = (p, like) => {
            const n = normal(p, middle);
            return dot(n, like) < 0 ? n.map((x) => -x) : n;
          };
          const u = oriented(ownPrimitive, n1), v = oriented(primitive, n2);
          angle = Math.min(180, (Math.atan2(norm(cross(u, v)), dot(u, v)) * 180) / Math.PI);
        }
        add(other, length, angle);
      }
    }
    return [...neighbours].map(([cluster, { edges, length, angleSum, angleWeight }]) => ({
      cluster, edges, length, angle: angleWeight > 0 ? angleSum / angleWeight : null,
    })).sort((x, y) => y.length - x.length || x.cluster - y.cluster);
  }

  /** The current border edges as [lower vertex, higher vertex] pairs. */
  borderEdges() {
    const { ends } = this.edges;
    return Array.from(this.border, (e) => [ends[2 * e], ends[2 * e + 1]]);
  }
}
