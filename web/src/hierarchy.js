// The merge tree in the page, and its cuts in linear time, as primseg's src/cut.cpp makes them:
// by count (the first F - K real merges applied; trailing merges joining components never) and
// by tolerance (top-down from each component's root, a node is kept whole when its RMS
// estimate is at most the tolerance).

export const TYPE_NAMES = ['plane', 'cylinder', 'sphere', 'cone', 'torus'];

/** Area of each triangle, input units squared. */
export function triangleAreas(positions, triangles) {
  const T = triangles.length / 3;
  const areas = new Float64Array(T);
  for (let t = 0; t < T; ++t) {
    const a = 3 * triangles[3 * t], b = 3 * triangles[3 * t + 1], c = 3 * triangles[3 * t + 2];
    const ux = positions[b] - positions[a], uy = positions[b + 1] - positions[a + 1],
      uz = positions[b + 2] - positions[a + 2];
    const vx = positions[c] - positions[a], vy = positions[c + 1] - positions[a + 1],
      vz = positions[c + 2] - positions[a + 2];
    const nx = uy * vz - uz * vy, ny = uz * vx - ux * vz, nz = ux * vy - uy * vx;
    areas[t] = 0.5 * Math.sqrt(nx * nx + ny * ny + nz * nz);
  }
  return areas;
}

/**
 * A level: `nodes[c]` is the tree node of cluster c (clusters in no particular order) and
 * `faceCluster[f]` the cluster of input face f, made on first use (a slider step does not need
 * it: it colours the clusters' ranges of the leaf order).
 */
export class Cut {
  constructor(nodes, tree) {
    this.nodes = nodes;
    this.tree = tree;
    this.labels = null;
    this.ids = null; // Tree.clusterIds, made on first use too: a cut never changes
  }
  get size() {
    return this.nodes.length;
  }
  get faceCluster() {
    if (!this.labels) {
      const { leafOrder, leafStart, faces } = this.tree;
      const labels = new Int32Array(this.tree.faceCount);
      this.nodes.forEach((node, c) => {
        for (let p = leafStart[node], end = p + faces[node]; p < end; ++p) labels[leafOrder[p]] = c;
      });
      this.labels = labels;
    }
    return this.labels;
  }
}

/** The first index in [low, high) of an increasing array whose value is not below `value`. */
export function lowerBound(sorted, value, low = 0, high = sorted.length) {
  while (low < high) {
    const middle = (low + high) >>> 1;
    if (sorted[middle] < value) low = middle + 1;
    else high = middle;
  }
  return low;
}

export class Tree {
  constructor(data) {
    const { header, children, triangles } = data;
    this.data = data;
    const F = (this.faceCount = header.faces);
    this.nodeCount = 2 * F - 1;
    this.realMerges = F - header.components;
    this.children = children;
    const faceOfTriangle = data.faceOfTriangle;
    this.faceOfTriangle = faceOfTriangle;
    this.triangleArea = triangleAreas(data.positions, triangles);

    const n = this.nodeCount;
    const parent = (this.parent = new Int32Array(n).fill(-1));
    const area = (this.area = new Float64Array(n));
    const faces = (this.faces = new Uint32Array(n));
    // Representative leaf: the larger child's, so that a cluster keeps its colour while smaller
    // ones merge into it.
    const representative = (this.representative = new Uint32Array(n));
    const T = triangles.length / 3;
    for (let t = 0; t < T; ++t) area[faceOfTriangle ? faceOfTriangle[t] : t] += this.triangleArea[t];
    for (let f = 0; f < F; ++f) {
      faces[f] = 1;
      representative[f] = f;
    }
    for (let i = 0; i < F - 1; ++i) {
      const a = children[2 * i], b = children[2 * i + 1], node = F + i;
      if (a >= node || b >= node) throw new Error(`merge ${i}: children must come before parents`);
      parent[a] = parent[b] = node;
      area[node] = area[a] + area[b];
      faces[node] = faces[a] + faces[b];
      representative[node] = representative[area[a] >= area[b] ? a : b];
    }
    // Component roots: the children of trailing merges that are not trailing themselves, or the
    // root.
    const roots = [];
    for (let node = 0; node < n; ++node) {
      const trailing = node >= F && node - F >= this.realMerges;
      const p = parent[node];
      if (!trailing && (p < 0 || p - F >= this.realMerges)) roots.push(node);
    }
    this.roots = Uint32Array.from(roots);
    // Leaf order: the leaves of every node are contiguous, from leafStart[node] (faces[node] of
    // them), leafOrder[position] = face. The last node is the root of the whole tree.
    const leafStart = (this.leafStart = new Uint32Array(n));
    for (let node = n - 1; node >= F; --node) {
      const a = children[2 * (node - F)], b = children[2 * (node - F) + 1];
      leafStart[a] = leafStart[node];
      leafStart[b] = leafStart[node] + faces[a];
    }
    this.leafOrder = new Uint32Array(F);
    for (let f = 0; f < F; ++f) this.leafOrder[leafStart[f]] = f;
    this.errorCurve = this.computeErrorCurve();
  }

  isLeaf(node) {
    return node < this.faceCount;
  }

  /** RMS distance estimate of a node to its primitive (input units). */
  rms(node) {
    if (node >= this.faceCount) return this.data.rms[node - this.faceCount];
    return this.data.leafRms ? this.data.leafRms[node] : 0;
  }

  /** Primitive type index of a node (leaves are planes). */
  type(node) {
    return node >= this.faceCount ? this.data.types[node - this.faceCount] : 0;
  }

  /** Index of a node among those whose primitive the page carries, or -1. O(log). */
  parameterIndex(node) {
    const nodes = this.data.parameterNodes;
    const i = lowerBound(nodes, node);
    return i < nodes.length && nodes[i] === node ? i : -1;
  }

  /**
   * The primitive primseg reports for a node as a cluster (the geometric fit), if the page
   * carries it: {type, point (relative to header.center), axis, radius, minorRadius, halfAngle}.
   */
  primitive(node) {
    const i = this.parameterIndex(node);
    if (i < 0) return null;
    const p = this.data.parameters.subarray(9 * i, 9 * i + 9);
    return {
      type: this.type(node),
      point: [p[0], p[1], p[2]],
      axis: [p[3], p[4], p[5]],
      radius: p[6],
      minorRadius: p[7],
      halfAngle: p[8],
    };
  }

  /** Exact RMS and maximum distance of a node's vertices to primitive(node), or null. */
  errors(node) {
    const i = this.parameterIndex(node);
    return i < 0 ? null : { rms: this.data.errors[2 * i], max: this.data.errors[2 * i + 1] };
  }

  /** Smallest number of clusters any cut has (one per connected component). */
  get minClusters() {
    return this.data.header.components;
  }

  /**
   * The level with K clusters, as primseg cut --clusters K: the first F - K real merges applied
   * (trailing merges joining components never). O(K): down from the root to the applied nodes.
   */
  cutByCount(K) {
    const F = this.faceCount;
    K = Math.max(1, Math.min(F, Math.round(K)));
    const end = F + Math.min(this.realMerges, F - K);
    const children = this.children;
    const nodes = [];
    const stack = [this.nodeCount - 1];
    while (stack.length) {
      const node = stack.pop();
      if (node < end) nodes.push(node);
      else stack.push(children[2 * (node - F) + 1], children[2 * (node - F)]);
    }
    return new Cut(Uint32Array.from(nodes), this);
  }

  /**
   * Whether a cut is the level cutByCount(cut.size) gives (a cut by tolerance may not be one):
   * it is when all its nodes are among that level's applied merges and leaves, since a partition
   * finer than a level with as many clusters is that level. O(K).
   */
  isCountCut(cut) {
    const F = this.faceCount, end = F + Math.min(this.realMerges, F - cut.size);
    return cut.nodes.every((node) => node < end);
  }

  /** The level of tolerance T (input units), as primseg cut --tolerance T. O(K). */
  cutByTolerance(tolerance) {
    const F = this.faceCount, children = this.children;
    const nodes = [];
    const stack = Array.from(this.roots).reverse();
    while (stack.length) {
      const node = stack.pop();
      if (node < F || this.rms(node) <= tolerance) {
        nodes.push(node);
      } else {
        const i = node - F;
        stack.push(children[2 * i + 1], children[2 * i]);
      }
    }
    return new Cut(Uint32Array.from(nodes), this);
  }

  // Orders clusters as primseg does: by decreasing area, ties by lowest face.
  compareClusters(cut, lowestFace, a, b) {
    const areaA = this.area[cut.nodes[a]], areaB = this.area[cut.nodes[b]];
    if (areaA !== areaB) return areaB - areaA;
    return lowestFace[a] - lowestFace[b];
  }

  lowestFaces(cut) {
    const lowest = new Int32Array(cut.size).fill(-1);
    const faceCluster = cut.faceCluster;
    for (let f = 0; f < faceCluster.length; ++f) if (lowest[faceCluster[f]] < 0) lowest[faceCluster[f]] = f;
    return lowest;
  }

  /** Cluster ids as primseg numbers them (by decreasing area): id of each cluster. O(K log K). */
  clusterIds(cut) {
    if (cut.ids) return cut.ids;
    const lowest = this.lowestFaces(cut);
    const order = Array.from({ length: cut.size }, (_, c) => c);
    order.sort((a, b) => this.compareClusters(cut, lowest, a, b));
    const ids = new Uint32Array(cut.size);
    order.forEach((c, rank) => (ids[c] = rank));
    cut.ids = ids;
    return ids;
  }

  /** The largest clusters of a cut (at most `count`), largest first. O(K · count). */
  largestClusters(cut, count) {
    const best = [];
    for (let c = 0; c < cut.size; ++c) {
      const a = this.area[cut.nodes[c]];
      if (best.length === count && a <= this.area[cut.nodes[best[count - 1]]]) continue;
      let i = best.length === count ? count - 1 : best.length;
      while (i > 0 && this.area[cut.nodes[best[i - 1]]] < a) {
        best[i] = best[i - 1];
        --i;
      }
      best[i] = c;
    }
    return best;
  }

  /**
   * Area-weighted RMS estimate of the whole mesh at each level: curve[K] for K in
   * [components, F] (entries below are those of K = components). O(F).
   */
  computeErrorCurve() {
    const F = this.faceCount, children = this.children, area = this.area;
    const curve = new Float64Array(F + 1);
    const square = (node) => this.rms(node) ** 2 * area[node];
    let sum = 0, total = 0;
    for (let f = 0; f < F; ++f) {
      sum += square(f);
      total += area[f];
    }
    total = total > 0 ? total : 1;
    curve[F] = Math.sqrt(Math.max(0, sum) / total);
    for (let i = 0; i < this.realMerges; ++i) {
      sum += square(F + i) - square(children[2 * i]) - square(children[2 * i + 1]);
      curve[F - i - 1] = Math.sqrt(Math.max(0, sum) / total);
    }
    for (let K = F - this.realMerges - 1; K >= 0; --K) curve[K] = curve[K + 1];
    return curve;
  }

  /** Largest RMS estimate among a cut's clusters. */
  largestRms(cut) {
    let highest = 0;
    for (const node of cut.nodes) highest = Math.max(highest, this.rms(node));
    return highest;
  }
}
