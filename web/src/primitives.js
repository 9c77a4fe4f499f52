// Fitted primitives in the page: distances (as primseg's Primitive::closest_point) for a
// cluster's exact errors, and surfaces clipped to the cluster's extent for display.
// A primitive: {type, point[3], axis[3], radius, minorRadius, halfAngle}; types as
// include/primseg/primitive.hpp: 0 plane, 1 cylinder, 2 sphere, 3 cone, 4 torus.

export const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
export const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const scale = (a, s) => [a[0] * s, a[1] * s, a[2] * s];
const add = (a, b) => [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
export const norm = (a) => Math.sqrt(dot(a, a));
export const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const normalized = (a) => {
  const n = norm(a);
  return n > 0 ? scale(a, 1 / n) : [1, 0, 0];
};

/** Two unit vectors completing the unit vector a to an orthonormal basis. */
function basis(a) {
  const helper = Math.abs(a[0]) < 0.9 ? [1, 0, 0] : [0, 1, 0];
  const u = normalized(cross(a, helper));
  return [u, cross(a, u)];
}

/** Euclidean distance from x to the primitive's surface. */
export function distance(p, x) {
  const d = sub(x, p.point), a = p.axis;
  switch (p.type) {
    case 0:
      return Math.abs(dot(a, d));
    case 1: {
      const along = dot(a, d);
      return Math.abs(norm(sub(d, scale(a, along))) - p.radius);
    }
    case 2:
      return Math.abs(norm(d) - p.radius);
    case 3: {
      const along = dot(a, d);
      const radial = sub(d, scale(a, along));
      const r = norm(radial);
      const radialDir = r > 0 ? scale(radial, 1 / r) : basis(a)[0];
      const generator = add(scale(a, Math.cos(p.halfAngle)), scale(radialDir, Math.sin(p.halfAngle)));
      const t = Math.max(0, dot(d, generator));
      return norm(sub(d, scale(generator, t)));
    }
    case 4: {
      const radial = sub(d, scale(a, dot(a, d)));
      const r = norm(radial);
      const ring = scale(r > 0 ? scale(radial, 1 / r) : basis(a)[0], p.radius);
      return Math.abs(norm(sub(d, ring)) - p.minorRadius);
    }
  }
  return NaN;
}

/** Unit normal of the surface at its point nearest x, as primseg's Primitive::normal: a plane's
 *  axis; away from the centre, axis or core circle for the other types. */
export function normal(p, x) {
  const d = sub(x, p.point), a = p.axis;
  const radialDirection = () => {
    const radial = sub(d, scale(a, dot(a, d)));
    return norm(radial) > 0 ? normalized(radial) : basis(a)[0];
  };
  switch (p.type) {
    case 0:
      return a;
    case 1:
      return radialDirection();
    case 2:
      return normalized(d);
    case 3:
      return sub(scale(radialDirection(), Math.cos(p.halfAngle)), scale(a, Math.sin(p.halfAngle)));
    case 4: {
      const toX = sub(d, scale(radialDirection(), p.radius));
      return norm(toX) > 0 ? normalized(toX) : a;
    }
  }
  return [NaN, NaN, NaN];
}

/**
 * Exact RMS and maximum distance of a cluster's vertices to a primitive, weighted as primseg
 * weighs them: area/3 per triangle corner, or 1/valence per corner for uniform weights.
 */
export function clusterErrors(p, positions, triangles, triangleIds, cornerWeight) {
  let sumWd2 = 0, sumW = 0, max = 0;
  for (const t of triangleIds) {
    for (let c = 0; c < 3; ++c) {
      const v = triangles[3 * t + c];
      const x = [positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]];
      const d = distance(p, x);
      const w = cornerWeight(t, v);
      sumWd2 += w * d * d;
      sumW += w;
      max = Math.max(max, d);
    }
  }
  return { rms: sumW > 0 ? Math.sqrt(sumWd2 / sumW) : 0, max };
}

/**
 * The angular interval covering every angle given (radians), as [start, length]: the
 * complement of the largest empty gap in a histogram. Linear time.
 */
function angularSpan(angles) {
  const bins = 720;
  const used = new Uint8Array(bins);
  for (const angle of angles) {
    const b = Math.floor(((angle / (2 * Math.PI)) % 1 + 1) % 1 * bins);
    used[Math.min(bins - 1, b)] = 1;
  }
  let bestStart = 0, bestLength = 0;
  for (let start = 0; start < bins; ++start) {
    if (used[start] || used[(start + bins - 1) % bins] === 0) continue;
    let length = 0;
    while (length < bins && !used[(start + length) % bins]) ++length;
    if (length > bestLength) [bestStart, bestLength] = [start, length];
  }
  // A gap of a few bins is the spacing of the tessellation, not an open side.
  if (bestLength < bins / 36) return [0, 2 * Math.PI];
  const step = (2 * Math.PI) / bins;
  return [(bestStart + bestLength) * step, (bins - bestLength) * step];
}

function range(values) {
  let low = Infinity, high = -Infinity;
  for (const v of values) {
    low = Math.min(low, v);
    high = Math.max(high, v);
  }
  return [low, high];
}

/** Triangles of a (rows+1) x (columns+1) grid of points given by surfacePoint(i/rows, j/columns). */
function grid(rows, columns, surfacePoint) {
  const vertices = [], indices = [];
  for (let i = 0; i <= rows; ++i)
    for (let j = 0; j <= columns; ++j) vertices.push(...surfacePoint(i / rows, j / columns));
  for (let i = 0; i < rows; ++i)
    for (let j = 0; j < columns; ++j) {
      const a = i * (columns + 1) + j, b = a + columns + 1;
      indices.push(a, b, a + 1, a + 1, b, b + 1);
    }
  return { vertices, indices };
}

/** Convex hull of 2D points (Andrew's monotone chain), counter-clockwise. */
function convexHull(points) {
  points.sort((p, q) => p[0] - q[0] || p[1] - q[1]);
  const turn = (o, a, b) => (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  const lower = [], upper = [];
  for (const p of points) {
    while (lower.length >= 2 && turn(lower[lower.length - 2], lower[lower.length - 1], p) <= 0) lower.pop();
    lower.push(p);
  }
  for (let i = points.length - 1; i >= 0; --i) {
    const p = points[i];
    while (upper.length >= 2 && turn(upper[upper.length - 2], upper[upper.length - 1], p) <= 0) upper.pop();
    upper.push(p);
  }
  return lower.slice(0, -1).concat(upper.slice(0, -1));
}

/**
 * A surface of the primitive covering the given points (an array of [x, y, z]): a plane patch
 * (the given triangle corners `patch`, flat xyz, projected on it; else the points' convex
 * hull), a sphere cap, a cylinder or cone segment, a piece of torus. Returns
 * {vertices: flat xyz, indices} or null when it cannot be drawn.
 */
export function primitiveSurface(p, points, patch = null) {
  if (points.length < 3) return null;
  const a = normalized(p.axis);
  const [u, v] = basis(a);
  const o = p.point;
  switch (p.type) {
    case 0: {
      // The cluster's own triangles projected on the plane: a patch with the cluster's exact
      // outline, holes and concave sides included.
      if (patch) {
        const vertices = [];
        for (let k = 0; k < patch.length; k += 3) {
          const x = [patch[k], patch[k + 1], patch[k + 2]];
          vertices.push(...sub(x, scale(a, dot(a, sub(x, o)))));
        }
        return { vertices, indices: Array.from({ length: patch.length / 3 }, (_, k) => k) };
      }
      const hull = convexHull(points.map((x) => [dot(sub(x, o), u), dot(sub(x, o), v)]));
      if (hull.length < 3) return null;
      const vertices = [], indices = [];
      for (const [s, t] of hull) vertices.push(...add(o, add(scale(u, s), scale(v, t))));
      for (let k = 1; k + 1 < hull.length; ++k) indices.push(0, k, k + 1);
      return { vertices, indices };
    }
    case 1: {
      const along = points.map((x) => dot(sub(x, o), a));
      const [t0, t1] = range(along);
      const [phi0, span] = angularSpan(points.map((x) => Math.atan2(dot(sub(x, o), v), dot(sub(x, o), u))));
      return grid(1, 48, (i, j) => {
        const phi = phi0 + span * j;
        return add(o, add(scale(a, t0 + (t1 - t0) * i),
          scale(add(scale(u, Math.cos(phi)), scale(v, Math.sin(phi))), p.radius)));
      });
    }
    case 2: {
      const directions = points.map((x) => normalized(sub(x, o)));
      const mean = directions.reduce(add, [0, 0, 0]);
      const m = norm(mean) > 1e-9 * directions.length ? normalized(mean) : a;
      let theta = 0;
      for (const d of directions) theta = Math.max(theta, Math.acos(Math.max(-1, Math.min(1, dot(d, m)))));
      const [mu, mv] = basis(m);
      return grid(16, 48, (i, j) => {
        const polar = theta * i, azimuth = 2 * Math.PI * j;
        const d = add(scale(m, Math.cos(polar)),
          scale(add(scale(mu, Math.cos(azimuth)), scale(mv, Math.sin(azimuth))), Math.sin(polar)));
        return add(o, scale(d, p.radius));
      });
    }
    case 3: {
      const along = points.map((x) => Math.max(0, dot(sub(x, o), a)));
      const [t0, t1] = range(along);
      const [phi0, span] = angularSpan(points.map((x) => Math.atan2(dot(sub(x, o), v), dot(sub(x, o), u))));
      const slope = Math.tan(p.halfAngle);
      return grid(1, 48, (i, j) => {
        const t = t0 + (t1 - t0) * i, phi = phi0 + span * j;
        return add(o, add(scale(a, t), scale(add(scale(u, Math.cos(phi)), scale(v, Math.sin(phi))), t * slope)));
      });
    }
    case 4: {
      const phis = [], psis = [];
      for (const x of points) {
        const d = sub(x, o);
        const h = dot(d, a);
        const ru = dot(d, u), rv = dot(d, v);
        phis.push(Math.atan2(rv, ru));
        psis.push(Math.atan2(h, Math.hypot(ru, rv) - p.radius));
      }
      const [phi0, phiSpan] = angularSpan(phis);
      const [psi0, psiSpan] = angularSpan(psis);
      return grid(16, 48, (i, j) => {
        const psi = psi0 + psiSpan * i, phi = phi0 + phiSpan * j;
        const ring = add(scale(u, Math.cos(phi)), scale(v, Math.sin(phi)));
        return add(o, add(scale(ring, p.radius + p.minorRadius * Math.cos(psi)), scale(a, p.minorRadius * Math.sin(psi))));
      });
    }
  }
  return null;
}

/** Normal and centroid of one face (a leaf's plane), from its triangles. */
export function facePlane(positions, triangles, triangleIds) {
  let n = [0, 0, 0], c = [0, 0, 0], total = 0;
  for (const t of triangleIds) {
    const corner = (k) => {
      const i = 3 * triangles[3 * t + k];
      return [positions[i], positions[i + 1], positions[i + 2]];
    };
    const [x, y, z] = [corner(0), corner(1), corner(2)];
    const areaVector = scale(cross(sub(y, x), sub(z, x)), 0.5);
    const area = norm(areaVector);
    n = add(n, areaVector);
    c = add(c, scale(add(add(x, y), z), area / 3));
    total += area;
  }
  return { type: 0, point: total > 0 ? scale(c, 1 / total) : c, axis: normalized(n), radius: 0, minorRadius: 0, halfAngle: 0 };
}
