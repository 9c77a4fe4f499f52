// The relations of a page written by `primseg view --regularize`: for every level of up to a
// number of clusters, the parallel, coaxial, orthogonal, equal-radius, coplanar, tangent and concentric sets
// `primseg cut --clusters K --regularize` finds, and the fits they make exact (layout in data.js).

import { lowerBound } from './hierarchy.js';

/** What each kind means, for the rows' tooltips (relations.hpp). */
export const RELATION_MEANINGS = {
  parallel: 'plane normals and cylinder axes made one direction',
  coaxial: 'cylinders made one axis line, each keeping its radius, and spheres centred on it',
  orthogonal: 'two directions made exactly orthogonal (the clusters before | against those after)',
  equal_radius: 'cylinders and spheres made one radius, each keeping its axis line or centre',
  coplanar: 'planes made one plane, each keeping its side: the fragments of one face',
  tangent: 'a cylinder made tangent to a plane or a parallel cylinder it borders: a fillet and a face or a boss it rounds',
  concentric: 'spheres made one centre, each keeping its radius: a ball and its socket',
};

export class LevelRelations {
  /** @param data the page's data (data.js), with `relations`; @param tree its Tree */
  constructor(data, tree) {
    this.r = data.relations;
    this.info = data.header.relations;
    this.tree = tree;
    this.first = this.info.firstClusters;
    this.last = this.first + this.info.levels - 1;
  }

  /** Whether the page has the relations of the level with K clusters. */
  covers(K) {
    return K >= this.first && K <= this.last;
  }

  /**
   * Level K's relations in primseg's order (by kind, then clusters): [{kind (its name), nodes
   * (tree nodes of its clusters), otherNodes (orthogonal: those of the other direction; else
   * empty), deviation (how far the clusters' own fits were from it: degrees for parallel and
   * orthogonal, input units otherwise)}], or null when the page does not cover K.
   */
  at(K) {
    if (!this.covers(K)) return null;
    const { levelOffsets, kinds, memberOffsets, members, firstSide, deviations } = this.r;
    const list = [];
    for (let i = levelOffsets[K - this.first]; i < levelOffsets[K - this.first + 1]; ++i) {
      const from = memberOffsets[i], split = from + firstSide[i], to = memberOffsets[i + 1];
      list.push({ kind: this.info.kinds[kinds[i]], nodes: Array.from(members.subarray(from, split)),
        otherNodes: Array.from(members.subarray(split, to)), deviation: deviations[i] });
    }
    return list;
  }

  /**
   * The fit of `node` at level K as its relations made it exact, in Tree.primitive's form, with
   * its exact errors: {primitive, errors: {rms, max}}, or null when no relation of level K
   * refitted it. O(log).
   */
  fit(K, node) {
    if (!this.covers(K)) return null;
    const { fitOffsets, fitNodes, fitParameters: p, fitErrors } = this.r;
    const end = fitOffsets[K - this.first + 1];
    const at = lowerBound(fitNodes, node, fitOffsets[K - this.first], end);
    if (at === end || fitNodes[at] !== node) return null;
    const i = 9 * at;
    return {
      primitive: { type: this.tree.type(node), point: [p[i], p[i + 1], p[i + 2]], axis: [p[i + 3], p[i + 4], p[i + 5]],
        radius: p[i + 6], minorRadius: p[i + 7], halfAngle: p[i + 8] },
      errors: { rms: fitErrors[2 * at], max: fitErrors[2 * at + 1] },
    };
  }
}
