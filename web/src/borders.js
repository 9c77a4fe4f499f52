// The "borders" lines of a level: the mesh edges between faces of different clusters, and the
// mesh's open boundary, drawn over the mesh: what `primseg segment --borders` writes as curves.
// The lines take their ends from the drawn mesh, so they follow a posed skeleton.

import * as THREE from 'three';

/**
 * Every mesh edge once: its two vertices, the triangles on it and, for drawing, the corners of
 * its first triangle in the drawn (non-indexed) geometry.
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
  return {
    count: ends.length / 2, ends: Uint32Array.from(ends), sideStart: Uint32Array.from(sideStart),
    side, cornerIndex: Uint32Array.from(cornerIndex),
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

  /** The current border edges as [lower vertex, higher vertex] pairs. */
  borderEdges() {
    const { ends } = this.edges;
    return Array.from(this.border, (e) => [ends[2 * e], ends[2 * e + 1]]);
  }
}
